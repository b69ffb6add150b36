/* The multi-frusta (4x4 block) traversal of the micro-rasterization methods against the per-pixel
 * traversal it replaces: the very same visible masks, for every kernel, buffer size and ISA cap, on the
 * built-in scene, the Quad and two real scenes; its instances (portable, AVX2, AVX-512) take the same
 * decisions (same masks and counters under the ISA-exact Bounds kernel); the shallow BVH is a faithful
 * collapse of the deep one. */
#include "testutil.h"
#include "shadow/method.h"
#include "primary/primary.h"
#include "visibility/receiver.h"
#include "accel/bvh.h"
#include "core/cpu.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const kernels[] = { "scanline", "bounds", "hierarchical" };

typedef struct masks {
    uint64_t *vis;
    int n, mask_words, n_counters;
    uint64_t cnt[MS_MAX_COUNTERS];
    const char *const *names;
    ms_isa kernel, trav;
} masks;

/* The visible masks of the points of a size x size view of sc by a micro-raster method through its
 * interface, with the given traversal and ISA cap. */
static masks method_masks(const ms_scene *sc, const char *method, int k, int size, ms_isa cap, ms_traversal trav)
{
    masks r;
    memset(&r, 0, sizeof r);
    ms_bvh bvh;
    assert_int_equal(ms_bvh_build(&bvh, sc->tri, sc->n_tris, 1), 0);
    ms_render_ctx ctx;
    tu_ctx_init(&ctx, sc, &bvh, size, size, k);
    ctx.isa_cap = cap;
    ctx.traversal = trav;
    const ms_shadow_method *sm = ms_find_shadow_method(method);
    assert_non_null(sm);
    char err[256];
    void *ss = NULL;
    int nq;
    ms_shadow_query *q = tu_frame_queries(&ctx, size, &nq);
    const size_t mw = (size_t)ctx.mask_words;
    uint64_t *front = calloc((size_t)nq * mw + 1, sizeof *front);
    r.vis = calloc((size_t)nq * mw + 1, sizeof *r.vis);
    assert_non_null(front);
    assert_non_null(r.vis);
    for (int i = 0; i < nq; i++) ms_front_mask(&ctx, &q[i], NULL, front + i * mw);
    assert_int_equal(sm->create(&ctx, &ss, err, sizeof err), 0);
    sm->isa_used(ss, &r.kernel, &r.trav);
    const char *const *names = sm->counter_names;
    r.n_counters = sm->n_counters;
    if (sm->counters_used) {
        const int n = sm->counters_used(ss, &names);
        if (n >= 0) r.n_counters = n;
    }
    r.names = names;
    assert_int_equal(sm->visibility(ss, &ctx, q, nq, front, r.vis, r.cnt), 0);
    sm->destroy(ss);
    free(front);
    free(q);
    ms_bvh_free(&bvh);
    r.n = nq;
    r.mask_words = (int)mw;
    return r;
}

static uint64_t counter(const masks *m, const char *name)
{
    for (int c = 0; c < m->n_counters; c++)
        if (!strcmp(m->names[c], name)) return m->cnt[c];
    fail_msg("no counter %s", name);
    return 0;
}

/* Block and per-pixel traversal: identical masks for each kernel and k under the run's ISA cap; with
 * all_caps, also under every lower cap the CPU runs (Scanline only: the kernels' ISA variants are the
 * kernels' tests). */
static void block_equals_pixel(const ms_scene *sc, const char *label, const int *ks, int nk, int size, int all_caps,
                               int want_clipped, int want_node_cull)
{
    const int run_cap = (int)ms_isa_capped(tu_isa_cap());
    for (int cap = MS_ISA_SCALAR; cap <= MS_ISA_AVX512; cap++) {
        if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
        if (cap != run_cap && !all_caps) continue;
        for (int m = 0; m < (cap == run_cap ? 3 : 1); m++)
            for (int ki = 0; ki < nk; ki++) {
                masks b = method_masks(sc, kernels[m], ks[ki], size, (ms_isa)cap, MS_TRAVERSAL_BLOCK);
                masks p = method_masks(sc, kernels[m], ks[ki], size, (ms_isa)cap, MS_TRAVERSAL_PIXEL);
                assert_int_equal(b.trav, cap);
                assert_int_equal(b.n, p.n);
                long differ = 0;
                for (size_t i = 0; i < (size_t)b.n * b.mask_words; i++) differ += b.vis[i] != p.vis[i];
                /* counters: 0 blocks, ..., the rasterizations (block_raster.h order, microraster.c names) */
                const uint64_t rb = counter(&b, "triangles_rasterized"), rp = counter(&p, "triangles_rasterized");
                printf("%-22s %-12s k=%-2d %-6s: %d points, block masks differ in %ld words; rasterized %llu vs %llu\n",
                       label, kernels[m], ks[ki], ms_isa_name((ms_isa)cap), b.n, differ,
                       (unsigned long long)rb, (unsigned long long)rp);
                assert_int_equal(differ, 0);
                /* The SIMD Scanline kernel's set-up shared by a block's pixels (block_raster_impl.h,
                 * br_scan_setup) must have run, or the comparison above proved nothing about it. */
                if (m == 0 && cap >= MS_ISA_AVX2) {
                    const uint64_t shared = counter(&b, "shared_setups"), clipped = counter(&b, "shared_setups_clipped");
                    printf("%-22s %-12s k=%-2d %-6s: %llu of the rasterizations set up for several pixels at once, "
                           "%llu of them with a clip edge\n", label, kernels[m], ks[ki], ms_isa_name((ms_isa)cap),
                           (unsigned long long)shared, (unsigned long long)clipped);
                    assert_true(shared > 0);
                    /* Likewise the clip edges' lanes of that set-up, wherever the scene has triangles that
                     * reach the near or far plane. */
                    if (want_clipped) assert_true(clipped > 0);
                }
                /* The coverage test at the nodes above the leaves, where the scene's blocks take it. */
                if (want_node_cull && m == 0) {
                    const uint64_t node = counter(&b, "node_pixels_culled");
                    printf("%-22s %-12s k=%-2d %-6s: %llu pixels culled above the leaves\n", label, kernels[m], ks[ki],
                           ms_isa_name((ms_isa)cap), (unsigned long long)node);
                    assert_true(node > 0);
                }
                free(b.vis);
                free(p.vis);
            }
    }
}

static void test_default_scene(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    const int ks[] = { 16, 32, 64 };
    block_equals_pixel(&sc, "default", ks, 3, 48, 1, 1, 0);
    ms_scene_free(&sc);
}

static void test_quad(void **state)
{
    (void)state;
    ms_scene sc;
    tu_make_quad(&sc);
    const int ks[] = { 16, 32, 64 };
    block_equals_pixel(&sc, "quad", ks, 3, 48, 1, 0, 0);
    ms_scene_free(&sc);
}

static void real_scene(const char *rel, int size, int want_clipped, int want_node_cull)
{
    if (!tu_have_shared_scenes()) skip();
    char path[4096], err[512];
    ms_scene sc;
    int rc = ms_scene_load(tu_shared_scene(path, sizeof path, rel), &sc, err, sizeof err);
    if (rc) fprintf(stderr, "%s\n", err);
    assert_int_equal(rc, 0);
    const int ks[] = { 32 };
    block_equals_pixel(&sc, rel, ks, 1, size, 0, want_clipped, want_node_cull);
    ms_scene_free(&sc);
}

static void test_bunny(void **state) { (void)state; real_scene("stanford-bunny/stanford-bunny.json", 64, 0, 1); }
static void test_biglight(void **state) { (void)state; real_scene("dabrovic-sponza/dabrovic-sponza-biglight.json", 64, 1, 0); }

/* The traversal's instances take the same decisions: under Bounds, whose kernels are bit for bit the
 * same on every ISA, the masks and every counter agree between the portable, AVX2 and AVX-512
 * traversals. */
static void test_isa_instances_identical(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    masks ref = method_masks(&sc, "bounds", 32, 64, MS_ISA_SCALAR, MS_TRAVERSAL_BLOCK);
    assert_int_equal(ref.trav, MS_ISA_SCALAR);
    assert_true(counter(&ref, "blocks") > 0);
    for (int cap = MS_ISA_AVX2; cap <= MS_ISA_AVX512; cap++) {
        if (!tu_isa_allowed((ms_isa)cap) || cap > (int)ms_cpu_isa()) continue;
        masks got = method_masks(&sc, "bounds", 32, 64, (ms_isa)cap, MS_TRAVERSAL_BLOCK);
        assert_int_equal(got.trav, cap);
        assert_int_equal(got.n, ref.n);
        assert_memory_equal(got.vis, ref.vis, (size_t)ref.n * ref.mask_words * sizeof *ref.vis);
        assert_int_equal(got.n_counters, ref.n_counters);
        /* Every counter of a decision; those ending in _ns are the blocks' measured time. */
        for (int c = 0; c < ref.n_counters; c++) {
            const size_t len = strlen(ref.names[c]);
            if (len < 3 || strcmp(ref.names[c] + len - 3, "_ns")) assert_int_equal(got.cnt[c], ref.cnt[c]);
        }
        printf("block traversal %s: masks and %d counters identical to the portable instance (%llu AABB tests)\n",
               ms_isa_name((ms_isa)cap), ref.n_counters, (unsigned long long)counter(&ref, "aabb_tests"));
        free(got.vis);
    }
    free(ref.vis);
    ms_scene_free(&sc);
}

/* The shallow BVH: every triangle in exactly one leaf, each leaf a subtree of at most max_leaf
 * triangles or a leaf of the deep tree, every node's box holding its triangles, pairs adjacent. */
static void check_shallow(const ms_bvh *b, int max_leaf)
{
    ms_bvh_shallow s;
    assert_int_equal(ms_bvh_shallow_build(&s, b, max_leaf), 0);
    assert_true(s.n_nodes <= b->n_nodes);
    unsigned char *seen = calloc(b->n_tris + 1, 1);
    assert_non_null(seen);
    uint32_t stack[2 * MS_BVH_STACK + 8];
    int sp = 0, depth_ok = 1;
    stack[sp++] = 0;
    uint32_t leaves = 0;
    while (sp) {
        const ms_bvh_node *n = &s.nodes[stack[--sp]];
        if (n->count) {
            leaves++;
            assert_true(n->first + n->count <= b->n_tris);
            for (uint32_t t = n->first; t < n->first + n->count; t++) {
                assert_int_equal(seen[t], 0);
                seen[t] = 1;
                for (int v = 0; v < 3; v++)
                    for (int a = 0; a < 3; a++) {
                        const float x = b->tri[9 * t + 3 * v + a];
                        assert_true(x >= n->bmin[a] && x <= n->bmax[a]);
                    }
            }
        } else {
            assert_true(n->first + 1 < s.n_nodes);
            for (int h = 0; h < 2; h++) {
                const ms_bvh_node *c = &s.nodes[n->first + (uint32_t)h];
                for (int a = 0; a < 3; a++) assert_true(c->bmin[a] >= n->bmin[a] && c->bmax[a] <= n->bmax[a]);
            }
            if (sp + 2 > (int)(sizeof stack / sizeof *stack)) { depth_ok = 0; break; }
            stack[sp++] = n->first;
            stack[sp++] = n->first + 1;
        }
    }
    assert_true(depth_ok);
    for (uint32_t t = 0; t < b->n_tris; t++) assert_int_equal(seen[t], 1);
    /* fewer leaves than the deep tree's when leaves may grow */
    uint32_t deep_leaves = 0;
    for (uint32_t i = 0; i < b->n_nodes; i++) deep_leaves += b->nodes[i].count > 0;
    printf("shallow BVH, max leaf %2d: %u nodes (deep %u), %u leaves (deep %u), depth %d (deep %d)\n", max_leaf,
           s.n_nodes, b->n_nodes, leaves, deep_leaves, s.depth, b->depth);
    assert_true(leaves <= deep_leaves);
    if (max_leaf >= 8 && b->n_tris > 64) assert_true(leaves < deep_leaves);
    free(seen);
    ms_bvh_shallow_free(&s);
}

static void test_shallow_bvh(void **state)
{
    (void)state;
    ms_scene sc;
    assert_int_equal(ms_scene_default(&sc), 0);
    ms_bvh b;
    assert_int_equal(ms_bvh_build(&b, sc.tri, sc.n_tris, 2), 0);
    const int sizes[] = { 1, 4, 8, 16 };
    for (int i = 0; i < 4; i++) check_shallow(&b, sizes[i]);
    ms_bvh_free(&b);
    ms_scene_free(&sc);
    /* a random soup */
    tu_rng rng = { 7 };
    const size_t n = 5000;
    float *tri = malloc(n * 9 * sizeof *tri);
    assert_non_null(tri);
    for (size_t t = 0; t < n; t++) {
        float c[3];
        for (int a = 0; a < 3; a++) c[a] = (float)(tu_rng_next(&rng) % 1000) * 0.01f;
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++) tri[9 * t + 3 * v + a] = c[a] + (float)(tu_rng_next(&rng) % 100) * 0.003f;
    }
    assert_int_equal(ms_bvh_build(&b, tri, n, 2), 0);
    for (int i = 0; i < 4; i++) check_shallow(&b, sizes[i]);
    ms_bvh_free(&b);
    free(tri);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shallow_bvh),
        cmocka_unit_test(test_default_scene),
        cmocka_unit_test(test_quad),
        cmocka_unit_test(test_isa_instances_identical),
        cmocka_unit_test(test_bunny),
        cmocka_unit_test(test_biglight),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
