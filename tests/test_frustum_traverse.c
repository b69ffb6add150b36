/* The frustum traversal's instances (scalar, AVX2, AVX-512) compute the same tests with the same
 * arithmetic: on every frame they must leave bit-identical buffers and identical counters (nodes
 * visited, culled by the frustum and by coverage, triangles, early outs), for k = 16, 32, 64 and each
 * combination of the coverage cull and the child order. Frames: the hit points of a small render, and
 * random points inside the scene's bounds (boxes straddling C's plane, frames near-singular). Also: the
 * ISA cap is obeyed and reported. Exits 77 after that when this CPU (or the run's cap) allows only one
 * instance; the shared scenes are skipped when absent. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "shadow/microraster/frustum_traverse.h"
#include "raster/raster.h"
#include "light/pattern.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_ISA 3

typedef struct isa_fns { const char *name[MAX_ISA]; ms_frustum_trace_fn fn[MAX_ISA][3]; int n; } isa_fns;

/* The instances this CPU runs (under the run's cap, MS_TEST_ISA): scalar always, then each SIMD one
 * the selector grants when capped at it. */
static isa_fns available(void)
{
    static const ms_isa wanted[] = { MS_ISA_AVX2, MS_ISA_AVX512 };
    isa_fns r = { { "scalar" }, { { 0 } }, 1 };
    for (int w = 0; w < 3; w++) r.fn[0][w] = ms_frustum_trace_select(16 << w, MS_ISA_SCALAR, NULL);
    for (int i = 0; i < 2; i++) {
        ms_isa chosen = MS_ISA_AUTO;
        ms_frustum_trace_select(16, wanted[i], &chosen);
        if (chosen == wanted[i] && tu_isa_allowed(wanted[i])) {
            r.name[r.n] = ms_isa_name(wanted[i]);
            for (int w = 0; w < 3; w++) r.fn[r.n][w] = ms_frustum_trace_select(16 << w, wanted[i], NULL);
            r.n++;
        }
    }
    return r;
}

/* The cap is obeyed and reported: scalar -> scalar; below the CPU -> the cap; above it or none -> the
 * CPU's best; each choice is that ISA's instance. */
static void test_isa_cap(void **state)
{
    (void)state;
    const ms_isa best = ms_cpu_isa();
    const ms_isa caps[] = { MS_ISA_AUTO, MS_ISA_SCALAR, MS_ISA_AVX2, MS_ISA_AVX512 };
    for (int c = 0; c < 4; c++)
        for (int k = 16; k <= 64; k *= 2) {
            const ms_isa want = caps[c] == MS_ISA_AUTO || caps[c] > best ? best : caps[c];
            ms_isa chosen = MS_ISA_AUTO;
            const ms_frustum_trace_fn fn = ms_frustum_trace_select(k, caps[c], &chosen);
            assert_int_equal(chosen, want);
            assert_non_null(fn);
            assert_ptr_equal(fn, ms_frustum_trace_isa(k, want));
        }
    assert_null(ms_frustum_trace_select(8, MS_ISA_AUTO, NULL));
    for (ms_isa isa = MS_ISA_SCALAR; isa <= MS_ISA_AVX512; isa = (ms_isa)(isa + 1))
        if (isa > best) assert_null(ms_frustum_trace_isa(32, isa));
}

typedef struct frames { ms_raster_frame *f; uint32_t *skip; int n; } frames;

/* Frames of a size x size render's hit points at k, plus n_random points in the scene's bounds. */
static frames make_frames(const ms_scene *sc, const ms_bvh *bvh, int k, int size, int n_random)
{
    ms_render_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    assert_int_equal(ms_camera_basis_init(&ctx.cam, &sc->camera, size, size), 0);
    ctx.scene = sc;
    ctx.bvh = bvh;
    ctx.light = sc->light;
    ctx.pattern = MS_PATTERN_GRID;
    ctx.k = k;
    ctx.samples = k * k;
    ctx.near = 1e-4f;
    ctx.far = 1.0f - 1e-4f;
    ctx.threads = 1;
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    assert_non_null(pm);
    void *ps = NULL;
    char err[256];
    assert_int_equal(pm->create(&ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc((size_t)size * size * sizeof *hits);
    assert_non_null(hits);
    pm->trace(ps, &ctx, 0, 0, size, size, hits);
    pm->destroy(ps);

    frames r = { malloc(((size_t)size * size + (size_t)n_random) * sizeof *r.f),
                 malloc(((size_t)size * size + (size_t)n_random) * sizeof *r.skip), 0 };
    assert_non_null(r.f);
    assert_non_null(r.skip);
    for (int i = 0; i < size * size; i++) {
        if (hits[i].prim == UINT32_MAX) continue;
        ms_grid g;
        ms_grid_for_pixel(&ctx.light, k, (uint32_t)(i % size), (uint32_t)(i / size), 0, &g);
        if (ms_raster_frame_init(&r.f[r.n], hits[i].p, &g, ctx.near, ctx.far, 0) != 0) continue;
        r.skip[r.n++] = hits[i].prim;
    }
    free(hits);
    const ms_bvh_node *root = &bvh->nodes[0];
    for (int i = 0; i < n_random; i++) {
        float c[3];
        for (int a = 0; a < 3; a++)
            c[a] = root->bmin[a] + ms_hash_unit(ms_hash3((uint32_t)i, (uint32_t)a, 77u)) * (root->bmax[a] - root->bmin[a]);
        ms_grid g;
        ms_grid_for_pixel(&ctx.light, k, (uint32_t)i, 3u, 0, &g);
        if (ms_raster_frame_init(&r.f[r.n], c, &g, ctx.near, ctx.far, 0) != 0) continue;
        r.skip[r.n++] = UINT32_MAX;
    }
    return r;
}

/* Every instance on every frame: buffers and counters equal to the scalar instance's. */
static void compare_on_scene(const ms_scene *sc, const char *label, int size, int n_random)
{
    isa_fns isa = available();
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 0), 0);
    static const int flag_sets[] = { MS_FT_CULL_OCCLUDED | MS_FT_ORDER_CHILDREN, MS_FT_CULL_OCCLUDED,
                                     MS_FT_ORDER_CHILDREN, 0 };
    for (int w = 0; w < 3; w++) {
        const int k = 16 << w;
        ms_raster_fn raster = ms_raster_kernel(MS_KERNEL_SCANLINE, k, tu_isa_cap(), NULL);
        assert_non_null(raster);
        frames fr = make_frames(sc, &bvh, k, size, n_random);
        /* all four flag sets at k = 32; the renderer's set at the other widths */
        const int n_sets = k == 32 ? 4 : 1;
        for (int fs = 0; fs < n_sets; fs++) {
            uint64_t total[MAX_ISA][MS_FT_COUNTERS];
            memset(total, 0, sizeof total);
            size_t differ_buf = 0, differ_cnt = 0;
            for (int i = 0; i < fr.n; i++) {
                _Alignas(64) uint64_t buf[MAX_ISA][64];
                uint64_t cnt[MAX_ISA][MS_FT_COUNTERS];
                memset(cnt, 0, sizeof cnt);
                for (int s = 0; s < isa.n; s++) {
                    ms_buffer_fill_visible(buf[s], k);
                    isa.fn[s][w](&bvh, &fr.f[i], raster, fr.skip[i], buf[s], cnt[s], flag_sets[fs]);
                    for (int c = 0; c < MS_FT_COUNTERS; c++) total[s][c] += cnt[s][c];
                }
                for (int s = 1; s < isa.n; s++) {
                    differ_buf += memcmp(buf[s], buf[0], (size_t)k * k / 8) != 0;
                    differ_cnt += memcmp(cnt[s], cnt[0], sizeof cnt[0]) != 0;
                }
            }
            printf("%-36s k=%-2d flags=%d %5d frames, %9llu nodes, %8llu triangles:", label, k, flag_sets[fs], fr.n,
                   (unsigned long long)total[0][MS_FT_NODES_VISITED], (unsigned long long)total[0][MS_FT_TRIANGLES]);
            for (int s = 1; s < isa.n; s++) printf(" %s", isa.name[s]);
            printf(" vs scalar: %zu frames differ in buffer, %zu in counters\n", differ_buf, differ_cnt);
            assert_int_equal(differ_buf, 0);
            assert_int_equal(differ_cnt, 0);
            for (int s = 1; s < isa.n; s++) assert_memory_equal(total[s], total[0], sizeof total[0]);
            assert_true(total[0][MS_FT_TRIANGLES] > 0);
        }
        free(fr.f);
        free(fr.skip);
    }
    ms_bvh_free(&bvh);
}

static void test_default_scene(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    compare_on_scene(&sc, "default", 40, 400);
    ms_scene_free(&sc);
}

static void shared_scene(const char *rel, int size, int n_random)
{
    if (!tu_have_shared_scenes()) skip();
    char path[4096], err[512];
    ms_scene sc;
    int rc = ms_scene_load(tu_shared_scene(path, sizeof path, rel), &sc, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    compare_on_scene(&sc, rel, size, n_random);
    ms_scene_free(&sc);
}

static void test_sponza(void **state) { (void)state; shared_scene("dabrovic-sponza/dabrovic-sponza.json", 40, 400); }
static void test_bunny(void **state) { (void)state; shared_scene("stanford-bunny/stanford-bunny.json", 32, 200); }
static void test_sibenik(void **state) { (void)state; shared_scene("sibenik/sibenik.json", 32, 200); }

int main(int argc, char **argv)
{
    isa_fns isa = available();
    const struct CMUnitTest cap_tests[] = { cmocka_unit_test(test_isa_cap) };
    const int rc = cmocka_run_group_tests(cap_tests, NULL, NULL);
    if (isa.n < 2) {
        printf("skipping the comparison: only the scalar frustum traversal runs here (CPU without AVX2, or "
               "MS_TEST_ISA=scalar)\n");
        return rc ? rc : 77;
    }
    printf("comparing the frustum traversal's instances:");
    for (int s = 0; s < isa.n; s++) printf(" %s", isa.name[s]);
    printf("%s\n", isa.n < MAX_ISA ? " (no AVX-512 on this CPU, or capped)" : "");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_scene),
        cmocka_unit_test(test_sponza),
        cmocka_unit_test(test_bunny),
        cmocka_unit_test(test_sibenik),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv) || rc;
}
