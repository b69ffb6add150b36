/* The interleaved pattern (Benthin & Wald 2009, sec. 4.5; issue 12, "Samples"):
 *  - the points: the 16 sets of N/16 are disjoint, each is a (0,m,2)-net in base 2 and together they are
 *    a (0,m+4,2)-net (oracle: counting the points in every elementary interval of the right volume); a
 *    pixel's world points are its set's (u,v) on the light, the same in every 4x4 block of the frame;
 *  - the filter on hand-made frames against a direct double-precision weighted mean: the centred window
 *    (1/2, 1, 1, 1, 1/2 per axis), weights by front count, neighbours off the pixel's plane, with another
 *    normal, missed or with no sample in front left out (only the rule for which neighbours lie in a
 *    pixel's plane is restated here, for the one frame whose normals do not match its points);
 *  - sample for sample: raytrace and embree give the same raw V and S on it (whole frames, filter off);
 *  - quality: filtered at N = 256 (16 rays per pixel) its mean absolute error in V and S against a
 *    4096-sample raytrace render (grid pattern) is smaller than that of plain stratified sampling with
 *    the same 16 rays per pixel, on the Quad and on the built-in scene (the filter must buy quality).
 * The filter trades noise for blur over a 5-pixel footprint, so it pays only where penumbrae are wider
 * than that: at 96x96 the Quad's penumbra is ~5 pixels wide and filtered V was worse than stratified 16
 * (MAE 0.0041 vs 0.0025; 128x128: 0.0024 vs 0.0025), at 192x192 better (0.0011 vs 0.0025), at 256x256
 * 0.0007 vs 0.0025 (measured before the filter's plane test became slope-aware; the Quad is one plane and
 * did not change). The quality test therefore renders the Quad at 256x256 and the built-in scene at
 * 192x192 (filtered 0.0029 vs 0.0060 for stratified 16; its 4096-sample raytrace reference costs ~10 s
 * under ASan, twice that at 256x256); the paper's frames are 1024x1024. */
#include "testutil.h"
#include "primary/primary.h"
#include "light/pattern.h"
#include "render/interleave_filter.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const ms_light L = { { 1, 5, -2 }, { 3, 0.5f, 0 }, { 0.8f, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };

/* 1 if the n points (32-bit fixed point) form a (0,m,2)-net in base 2, n = 2^m: for every split
 * d + (m - d) = m, each of the 2^d x 2^(m-d) elementary intervals holds exactly one point. */
static int is_net(const uint32_t *u, const uint32_t *v, int n, int m, char *why, size_t wl)
{
    int *count = calloc((size_t)n, sizeof *count);
    assert_non_null(count);
    int ok = 1;
    for (int d = 0; d <= m && ok; d++) {
        memset(count, 0, (size_t)n * sizeof *count);
        for (int i = 0; i < n; i++) {
            const uint32_t a = d ? u[i] >> (32 - d) : 0, b = m - d ? v[i] >> (32 - (m - d)) : 0;
            count[(a << (m - d)) | b]++;
        }
        for (int c = 0; c < n && ok; c++)
            if (count[c] != 1) {
                snprintf(why, wl, "intervals 2^-%d x 2^-%d: cell %d holds %d points", d, m - d, c, count[c]);
                ok = 0;
            }
    }
    free(count);
    return ok;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static void test_sets_are_nets(void **st)
{
    (void)st;
    const int Ns[3] = { 256, 1024, 4096 };
    const uint32_t seeds[3] = { 0, 1, 0xDEADBEEFu };
    char why[128];
    for (int ni = 0; ni < 3; ni++)
        for (int si = 0; si < 3; si++) {
            const int N = Ns[ni], n = N / 16, m = ni * 2 + 4;   /* n = 2^m */
            uint32_t *u = malloc(sizeof *u * N), *v = malloc(sizeof *v * N);
            uint64_t *key = malloc(sizeof *key * N);
            assert_non_null(u);
            assert_non_null(v);
            assert_non_null(key);
            for (int s = 0; s < 16; s++) {
                ms_interleaved_uv(N, s, seeds[si], u + s * n, v + s * n);
                if (!is_net(u + s * n, v + s * n, n, m, why, sizeof why))
                    fail_msg("N=%d seed %u: set %d is not a (0,%d,2)-net: %s", N, seeds[si], s, m, why);
            }
            if (!is_net(u, v, N, m + 4, why, sizeof why))
                fail_msg("N=%d seed %u: the 16 sets together are not a (0,%d,2)-net: %s", N, seeds[si], m + 4, why);
            /* disjoint: no point twice (implied by the net property; checked on its own) */
            for (int i = 0; i < N; i++) key[i] = (uint64_t)u[i] << 32 | v[i];
            qsort(key, (size_t)N, sizeof *key, cmp_u64);
            for (int i = 1; i < N; i++) assert_true(key[i] != key[i - 1]);
            free(u);
            free(v);
            free(key);
        }
    /* the seed moves the points (a digital shift), and the sets differ */
    uint32_t a[16], b[16], c[16], d[16];
    ms_interleaved_uv(256, 3, 0, a, b);
    ms_interleaved_uv(256, 3, 1, c, d);
    assert_memory_not_equal(a, c, sizeof a);
    ms_interleaved_uv(256, 4, 0, c, d);
    assert_memory_not_equal(a, c, sizeof a);
}

/* A pixel's world points: its set's (u,v) mapped onto the light, corner + u edge_s + v edge_t; the same
 * for every pixel of the frame with the same (x & 3, y & 3), whatever the 4x4 block. */
static void test_pixel_points(void **st)
{
    (void)st;
    const int k = 32, N = k * k, n = N / 16;
    assert_int_equal(ms_pattern_spp(MS_PATTERN_INTERLEAVED, k), n);
    float *xyz = malloc(sizeof(float) * 3 * n), *other = malloc(sizeof(float) * 3 * n);
    uint32_t u[64], v[64];
    assert_non_null(xyz);
    assert_non_null(other);
    for (uint32_t py = 0; py < 8; py++)
        for (uint32_t px = 0; px < 8; px++) {
            const int set = (int)(px % 4 + 4 * (py % 4));
            assert_int_equal(ms_interleaved_set(px, py), set);
            ms_pattern_points(MS_PATTERN_INTERLEAVED, &L, k, px, py, 9, xyz);
            ms_interleaved_uv(N, set, 9, u, v);
            for (int i = 0; i < n; i++) {
                const double s = u[i] / 4294967296.0, t = v[i] / 4294967296.0;
                const double want[3] = { L.corner.x + s * L.edge_s.x + t * L.edge_t.x, L.corner.y + s * L.edge_s.y + t * L.edge_t.y,
                                         L.corner.z + s * L.edge_s.z + t * L.edge_t.z };
                for (int c = 0; c < 3; c++)
                    if (fabs(xyz[3 * i + c] - want[c]) > 1e-5 * (1.0 + fabs(want[c])))
                        fail_msg("pixel (%u,%u) point %d axis %d: %.7f, expected %.7f", px, py, i, c, xyz[3 * i + c], want[c]);
            }
            ms_pattern_points(MS_PATTERN_INTERLEAVED, &L, k, px + 4 * 37, py + 4 * 11, 9, other);
            assert_memory_equal(xyz, other, sizeof(float) * 3 * n);
        }
    free(xyz);
    free(other);
    /* the samples accepted per pattern */
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_INTERLEAVED, 256), 16);
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_INTERLEAVED, 4096), 256);
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_INTERLEAVED, 64), 0);
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_STRATIFIED, 16), 16);
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_STRATIFIED, 64), 64);
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_GRID, 64), 0);
    assert_int_equal(ms_pattern_samples_per_pixel(MS_PATTERN_GRID, 1024), 1024);
    assert_int_equal(ms_pattern_samples_per_pixel((ms_pattern)7, 1024), 0);
}

/* Hand-made frames for the filter: pixel (x, y) hits the plane y = 0 at (x, 0, y) with normal +y, unless
 * `kind` says otherwise for x >= W/2: 1 a parallel plane 0.5 higher (a step), 2 a normal tilted by 30
 * degrees (points still on y = 0), 3 a miss. */
enum { FW = 12, FH = 10 };
static void filter_frame(int kind, ms_hit *h, uint16_t *front, float *v, float *s, tu_rng *rng)
{
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            const int i = y * FW + x, right = x >= FW / 2;
            ms_hit *c = &h[i];
            c->prim = 0;
            c->p[0] = (float)x; c->p[1] = kind == 1 && right ? 0.5f : 0.0f; c->p[2] = (float)y;
            c->n[0] = 0.0f; c->n[1] = 1.0f; c->n[2] = 0.0f;
            if (kind == 2 && right) { c->n[0] = 0.5f; c->n[1] = 0.8660254f; }
            front[i] = (uint16_t)(1 + tu_rng_next(rng) % 16);
            v[i] = (float)(tu_rng_next(rng) % 1000) / 999.0f;
            s[i] = (float)(tu_rng_next(rng) % 1000) / 999.0f;
            if (kind == 3 && right) { c->prim = UINT32_MAX; front[i] = 0; v[i] = s[i] = -1.0f; }
        }
    front[3 * FW + 2] = 0;   /* a pixel with no sample in front: V = S = 0 by definition */
    v[3 * FW + 2] = s[3 * FW + 2] = 0.0f;
}

static void test_filter(void **st)
{
    (void)st;
    tu_rng rng = { 99 };
    for (int kind = 0; kind < 4; kind++) {
        ms_hit h[FW * FH];
        uint16_t front[FW * FH];
        float v[FW * FH], s[FW * FH], v1[FW * FH], s1[FW * FH], sp[FW * FH], sp1[FW * FH], v2[FW * FH], s2[FW * FH];
        filter_frame(kind, h, front, v, s, &rng);
        for (int i = 0; i < FW * FH; i++) sp[i] = s[i] < 0.0f ? s[i] : (float)(tu_rng_next(&rng) % 1000) / 999.0f;   /* S_spec */
        memcpy(v1, v, sizeof v);
        memcpy(s1, s, sizeof s);
        memcpy(sp1, sp, sizeof sp);
        memcpy(v2, v, sizeof v);
        memcpy(s2, s, sizeof s);
        assert_int_equal(ms_interleave_filter(FW, FH, h, front, v1, s1, sp1, 2), 0);
        /* without S_spec: V and S bit for bit as with it (one pass filters the three) */
        assert_int_equal(ms_interleave_filter(FW, FH, h, front, v2, s2, NULL, 1), 0);
        assert_memory_equal(v1, v2, sizeof v1);
        assert_memory_equal(s1, s2, sizeof s1);
        /* every instance this CPU runs gives the same floats (the frame is narrower than one 16-lane chunk,
         * so each row is a partial chunk; the scene tests below cover whole ones) */
        for (ms_isa isa = MS_ISA_SCALAR; isa <= ms_cpu_isa(); isa = (ms_isa)(isa + 1)) {
            float vi[FW * FH], si[FW * FH], spi[FW * FH];
            assert_int_equal(ms_interleave_filter_rows_isa(isa, FW, FH, h, front, v, s, sp, 0, FH, 0, FH, vi, si, spi, 1), 0);
            assert_memory_equal(vi, v1, sizeof vi);
            assert_memory_equal(si, s1, sizeof si);
            assert_memory_equal(spi, sp1, sizeof spi);
        }
        for (int y = 0; y < FH; y++)
            for (int x = 0; x < FW; x++) {
                const int i = y * FW + x, right = x >= FW / 2;
                double wv = 0, ws = 0, wsp = 0, w = 0;
                for (int dy = -2; dy <= 2; dy++)
                    for (int dx = -2; dx <= 2; dx++) {
                        const int xx = x + dx, yy = y + dy, j = yy * FW + xx;
                        if (xx < 0 || yy < 0 || xx >= FW || yy >= FH || !front[j]) continue;
                        if (kind && (xx >= FW / 2) != right) continue;   /* the other surface, or a miss */
                        /* a tilted normal on the points of y = 0: only the neighbours along z are in its plane */
                        if (kind == 2 && right && dx != 0) continue;
                        const double t = (dx == -2 || dx == 2 ? 0.5 : 1.0) * (dy == -2 || dy == 2 ? 0.5 : 1.0) * front[j];
                        w += t; wv += t * v[j]; ws += t * s[j]; wsp += t * sp[j];
                    }
                double ev = w > 0 ? wv / w : v[i], es = w > 0 ? ws / w : s[i], esp = w > 0 ? wsp / w : sp[i];
                if (!front[i]) { ev = es = v[i]; esp = sp[i]; }   /* misses and pixels with nothing in front stay */
                if (fabs(v1[i] - ev) > 1e-5 || fabs(s1[i] - es) > 1e-5 || fabs(sp1[i] - esp) > 1e-5)
                    fail_msg("kind %d pixel (%d,%d): filtered V %.6f S %.6f S_spec %.6f, expected %.6f %.6f %.6f", kind, x, y,
                             v1[i], s1[i], sp1[i], ev, es, esp);
            }
    }
}

/* The filter's instances on a frame of whole and partial 16-pixel chunks (37 wide): a rough surface with
 * normals near +y (some neighbours off the tolerances), misses and pixels with nothing in front; every
 * instance bit for bit as the portable one, with and without S_spec. */
static void test_filter_instances(void **st)
{
    (void)st;
    enum { W2 = 37, H2 = 9, N2 = W2 * H2 };
    tu_rng rng = { 7 };
    ms_hit h[N2];
    uint16_t front[N2];
    float v[N2], s[N2], sp[N2];
    for (int i = 0; i < N2; i++) {
        const float r = (float)(tu_rng_next(&rng) % 1000) / 1000.0f;
        h[i].prim = tu_rng_next(&rng) % 17 == 0 ? UINT32_MAX : 0;
        h[i].p[0] = (float)(i % W2); h[i].p[1] = 0.008f * r; h[i].p[2] = (float)(i / W2);
        const float r2 = (float)(tu_rng_next(&rng) % 1000) / 1000.0f;
        h[i].n[0] = 0.012f * r2; h[i].n[1] = 1.0f; h[i].n[2] = -0.004f * r2;
        front[i] = h[i].prim == UINT32_MAX ? 0 : (uint16_t)(tu_rng_next(&rng) % 17);
        v[i] = h[i].prim == UINT32_MAX ? -1.0f : (float)(tu_rng_next(&rng) % 1000) / 999.0f;
        s[i] = h[i].prim == UINT32_MAX ? -1.0f : (float)(tu_rng_next(&rng) % 1000) / 999.0f;
        sp[i] = h[i].prim == UINT32_MAX ? -1.0f : (float)(tu_rng_next(&rng) % 1000) / 999.0f;
    }
    float rv[N2], rs[N2], rsp[N2], vi[N2], si[N2], spi[N2];
    assert_int_equal(ms_interleave_filter_rows_isa(MS_ISA_SCALAR, W2, H2, h, front, v, s, sp, 0, H2, 0, H2, rv, rs, rsp, 2), 0);
    int changed = 0, off_plane = 0;
    for (int i = 0; i < N2; i++) changed += rv[i] != v[i];
    assert_true(changed > N2 / 2);   /* the filter did average */
    /* and the frame has horizontal neighbours off each other's tangent plane (the tolerance decides) */
    for (int i = 0; i + 1 < N2; i++) {
        const double d[3] = { h[i + 1].p[0] - h[i].p[0], h[i + 1].p[1] - h[i].p[1], h[i + 1].p[2] - h[i].p[2] };
        off_plane += fabs(d[0] * h[i].n[0] + d[1] * h[i].n[1] + d[2] * h[i].n[2]) > 0.01 * sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    if (!(off_plane > 10 && off_plane < N2 - 10)) fail_msg("%d of %d neighbours off the plane", off_plane, N2);
    for (ms_isa isa = MS_ISA_SCALAR; isa <= ms_cpu_isa(); isa = (ms_isa)(isa + 1)) {
        assert_int_equal(ms_interleave_filter_rows_isa(isa, W2, H2, h, front, v, s, sp, 0, H2, 0, H2, vi, si, spi, 2), 0);
        assert_memory_equal(vi, rv, sizeof vi);
        assert_memory_equal(si, rs, sizeof si);
        assert_memory_equal(spi, rsp, sizeof spi);
        /* rows 3 .. 7 alone, from the window of rows 1 .. 8 (a streamed band) */
        float bv[N2], bs[N2];
        const size_t w0 = (size_t)1 * W2;
        assert_int_equal(ms_interleave_filter_rows_isa(isa, W2, H2, h + w0, front + w0, v + w0, s + w0, NULL, 1, 8, 3, 7, bv, bs, NULL, 1), 0);
        assert_memory_equal(bv, rv + 3 * W2, sizeof(float) * 4 * W2);
        assert_memory_equal(bs, rs + 3 * W2, sizeof(float) * 4 * W2);
    }
}

static void render(const ms_scene *sc, const char *method, ms_pattern pat, int samples, int size, int no_filter,
                   ms_frame *f)
{
    ms_render_options o;
    tu_render_options_default(&o);
    o.method = method;
    o.pattern = pat;
    o.samples = samples;
    o.width = o.height = size;
    o.seed = 5;
    o.no_filter = no_filter;
    char err[512] = "";
    const int rc = ms_render(sc, &o, f, err, sizeof err);
    if (rc) fail_msg("ms_render(%s, %s, %d): %s", method, ms_pattern_name(pat), samples, err);
    assert_int_equal(f->stats.samples, samples);
}

/* raytrace and embree on the interleaved pattern, raw: the tolerance of tests/test_embree.c (ties only:
 * no pixel off by more than one of its samples, at most 0.1% of the pixels off at all, S equal where V
 * is); then filtered: the filter sees the same inputs, so it moves them alike. */
static void agree_on(const ms_scene *sc, const char *name, int samples, int size)
{
#ifdef MS_HAVE_EMBREE
    long raw_differ = 0;
    for (int filt = 0; filt < 2; filt++) {
        ms_frame rt, eb;
        render(sc, "raytrace", MS_PATTERN_INTERLEAVED, samples, size, !filt, &rt);
        render(sc, "embree", MS_PATTERN_INTERLEAVED, samples, size, !filt, &eb);
        assert_int_equal(rt.stats.samples_per_pixel, samples / 16);
        assert_string_equal(rt.stats.pattern, "interleaved");
        assert_true(filt ? rt.stats.filter_s > 0.0 : rt.stats.filter_s == 0.0);
        tu_agreement g = tu_compare_frames(&rt, &eb);
        fprintf(stderr, "%s interleaved N=%d %dx%d %s: %ld of %ld pixels differ (max |dV| %g x front, max |dS| %g), "
                "%ld by more than one sample, %ld with S differing where V agrees\n",
                name, samples, size, size, filt ? "filtered" : "raw", g.differ, g.pixels, g.max_steps, g.max_ds,
                g.beyond_one, g.s_differ_same_v);
        assert_int_equal(g.miss_mismatch, 0);
        assert_true(g.pixels > 0);
        if (!filt) {
            assert_int_equal(g.beyond_one, 0);
            assert_true(g.differ * 1000 <= g.pixels);
            assert_true(g.s_differ_same_v * 1000 <= g.pixels);
            assert_int_equal(g.s_beyond, 0);
            assert_memory_equal(rt.front, eb.front, sizeof *rt.front * (size_t)size * size);
            /* front counts are of the pixel's own N/16 samples */
            for (int i = 0; i < size * size; i++) assert_true(rt.front[i] <= samples / 16);
            raw_differ = g.differ;
        } else {
            /* the filter is a function of the raw values and the hits: a raw pixel that differs reaches
             * the 5x5 window around it, no further */
            assert_true(g.differ <= 25 * raw_differ);
        }
        ms_frame_free(&rt);
        ms_frame_free(&eb);
    }
#else
    (void)sc; (void)name; (void)samples; (void)size;
    fprintf(stderr, "embree not compiled in: raytrace/embree agreement not checked\n");
#endif
}

static void test_raytrace_embree_agree(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    agree_on(&sc, "quad", 256, 64);
    agree_on(&sc, "quad", 1024, 48);
    ms_scene_free(&sc);
    assert_int_equal(ms_scene_default(&sc), 0);
    agree_on(&sc, "built-in", 256, 64);
    ms_scene_free(&sc);
    if (tu_have_shared_scenes()) {
        char path[4096], err[512];
        tu_shared_scene(path, sizeof path, "dabrovic-sponza/dabrovic-sponza.json");
        if (ms_scene_load(path, &sc, err, sizeof err)) fail_msg("%s", err);
        agree_on(&sc, "dabrovic-sponza", 256, 48);
        ms_scene_free(&sc);
    }
}

/* The CLI: --pattern interleaved gives the library's filtered V, --no-filter the raw one (both read back
 * from --vis), and the two differ. */
static void test_cli(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("interleaved_cli");
    char pf[4096], pr[4096], png[4096], err[1024];
    tu_path(pf, sizeof pf, dir, "filtered.pfm");
    tu_path(pr, sizeof pr, dir, "raw.pfm");
    tu_path(png, sizeof png, dir, "out.png");
    const char *a1[] = { "--method", "raytrace", "--pattern", "interleaved", "--samples", "256", "--width", "32",
                         "--height", "32", "--seed", "5", "--vis", pf, "-o", png, "--quiet", NULL };
    const char *a2[] = { "--method", "raytrace", "--pattern", "interleaved", "--samples", "256", "--width", "32",
                         "--height", "32", "--seed", "5", "--vis", pr, "-o", png, "--no-filter", "--quiet", NULL };
    assert_int_equal(tu_run_cli(a1, err, sizeof err), 0);
    assert_int_equal(tu_run_cli(a2, err, sizeof err), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_showcase(&sc), 0);   /* the CLI's built-in scene */
    const char *paths[2] = { pf, pr };
    float *got[2];
    for (int nf = 0; nf < 2; nf++) {
        int w, h;
        got[nf] = tu_read_pfm(paths[nf], &w, &h);
        assert_non_null(got[nf]);
        assert_int_equal(w, 32);
        assert_int_equal(h, 32);
        ms_frame f;
        render(&sc, "raytrace", MS_PATTERN_INTERLEAVED, 256, 32, nf, &f);
        assert_memory_equal(got[nf], f.vis, sizeof(float) * 32 * 32);
        ms_frame_free(&f);
    }
    assert_memory_not_equal(got[0], got[1], sizeof(float) * 32 * 32);
    free(got[0]);
    free(got[1]);
    ms_scene_free(&sc);
}

typedef struct mae { double v, s; long n; } mae;

/* Mean absolute error of V and S against the reference over the pixels the reference sees. */
static mae mae_of(const ms_frame *f, const ms_frame *ref)
{
    mae e = { 0, 0, 0 };
    for (int i = 0; i < ref->width * ref->height; i++) {
        if (ref->vis[i] < 0.0f) continue;
        assert_true(f->vis[i] >= 0.0f);   /* same primary rays */
        e.v += fabs((double)f->vis[i] - ref->vis[i]);
        e.s += fabs((double)f->shadow[i] - ref->shadow[i]);
        e.n++;
    }
    if (e.n) { e.v /= (double)e.n; e.s /= (double)e.n; }
    return e;
}

static void quality_on(const ms_scene *sc, const char *name, int size)
{
    ms_frame ref, il, raw, s16;
    /* the converged answer: the 4096-sample grid, by scanline (raytrace's V and S sample for sample, which
     * test_visibility and test_scenes check; a fraction of raytrace's time under ASan) */
    render(sc, "scanline", MS_PATTERN_GRID, 4096, size, 0, &ref);
    render(sc, "raytrace", MS_PATTERN_INTERLEAVED, 256, size, 0, &il);
    render(sc, "raytrace", MS_PATTERN_INTERLEAVED, 256, size, 1, &raw);
    render(sc, "raytrace", MS_PATTERN_STRATIFIED, 16, size, 0, &s16);
    assert_int_equal(s16.stats.samples_per_pixel, 16);
    assert_int_equal(il.stats.samples_per_pixel, 16);
    const mae e_il = mae_of(&il, &ref), e_raw = mae_of(&raw, &ref), e16 = mae_of(&s16, &ref);
    fprintf(stderr, "%s %dx%d, MAE against the grid 4096 over %ld pixels (V / S):\n"
            "  interleaved N=256 filtered (16 rays/pixel) %.5f / %.5f\n"
            "  interleaved N=256 raw      (16 rays/pixel) %.5f / %.5f\n"
            "  stratified 16                              %.5f / %.5f\n",
            name, size, size, e_il.n, e_il.v, e_il.s, e_raw.v, e_raw.s, e16.v, e16.s);
    assert_true(e_il.n > 0);
    assert_true(e_il.v < e16.v);
    assert_true(e_il.s < e16.s);
    assert_true(e_il.v < e_raw.v);   /* the filter buys it: raw, the sets are 16 points as well */
    ms_frame_free(&ref);
    ms_frame_free(&il);
    ms_frame_free(&raw);
    ms_frame_free(&s16);
}

static void test_quality(void **st)
{
    (void)st;
    ms_scene sc;
    tu_make_quad(&sc);
    quality_on(&sc, "quad", 256);
    ms_scene_free(&sc);
    assert_int_equal(ms_scene_default(&sc), 0);
    quality_on(&sc, "built-in", 192);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sets_are_nets),
        cmocka_unit_test(test_pixel_points),
        cmocka_unit_test(test_filter),
        cmocka_unit_test(test_filter_instances),
        cmocka_unit_test(test_raytrace_embree_agree),
        cmocka_unit_test(test_cli),
        cmocka_unit_test(test_quality),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
