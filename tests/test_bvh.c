/* BVH closest-hit and any-hit against brute force over every triangle of the soup.
 *
 * Oracle: a linear loop over the *source* soup (mapped through tri_source), testing each triangle with
 * ms_intersect_triangle, so that the traversal (box culling, ordering, early exits, the stack) is what
 * is under test. ms_intersect_triangle itself is checked separately against a double-precision
 * barycentric test on rays that are not near any edge. Rays: thousands per soup, random, axis-parallel,
 * along triangle edges, through vertices, and finite segments with random skip triangles. The same for a BVH
 * pruned to a subset of its triangles (ms_bvh_filter), against brute force over that subset. */
#include "testutil.h"
#include "accel/bvh.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static float rnd(tu_rng *r) { return (float)((tu_rng_next(r) >> 40) * (1.0 / 16777216.0)); }   /* [0,1) */
static float rnd_in(tu_rng *r, float lo, float hi) { return lo + (hi - lo) * rnd(r); }

/* Soup kinds. */
enum { SOUP_RANDOM, SOUP_GRID, SOUP_CLUSTER, SOUP_LONG };

static float *make_soup(int kind, size_t n, tu_rng *r, size_t *out_n)
{
    float *t = calloc(9 * (n + 64), sizeof(float));
    size_t m = 0;
    if (kind == SOUP_RANDOM) {
        /* Triangles of many sizes around random centres. */
        for (; m < n; m++) {
            float c[3] = { rnd_in(r, -10, 10), rnd_in(r, -10, 10), rnd_in(r, -10, 10) };
            float s = rnd(r) < 0.1f ? rnd_in(r, 2, 8) : rnd_in(r, 0.05f, 1.5f);
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) t[9 * m + 3 * v + a] = c[a] + rnd_in(r, -s, s);
        }
    } else if (kind == SOUP_GRID) {
        /* Axis-aligned unit quads (two triangles each) in the planes y = 0, x = 3 and z = -2: shared
         * edges and vertices, boxes of zero thickness. */
        int g = 12;
        for (int i = 0; i < g && m + 6 <= n; i++)
            for (int j = 0; j < g && m + 6 <= n; j++) {
                float a = (float)(i - g / 2), b = (float)(j - g / 2);
                const float q[3][4][3] = {
                    { { a, 0, b }, { a + 1, 0, b }, { a + 1, 0, b + 1 }, { a, 0, b + 1 } },
                    { { 3, a, b }, { 3, a + 1, b }, { 3, a + 1, b + 1 }, { 3, a, b + 1 } },
                    { { a, b, -2 }, { a + 1, b, -2 }, { a + 1, b + 1, -2 }, { a, b + 1, -2 } },
                };
                for (int p = 0; p < 3; p++) {
                    const int idx[6] = { 0, 1, 2, 0, 2, 3 };
                    for (int v = 0; v < 6; v++) memcpy(t + 9 * m + 3 * (v % 3) + 9 * (v / 3), q[p][idx[v]], 3 * sizeof(float));
                    m += 2;
                }
            }
    } else if (kind == SOUP_CLUSTER) {
        /* Most triangles piled into a tiny region (many identical), a few far away: stresses the
         * build's depth limit and leaves that cannot be split. */
        for (; m < n; m++) {
            if (m % 5 == 0) {
                /* The same small triangle (0.01,0,0) (0.012,0,0) (0.01,0.002,0.001), over and over. */
                const float same[9] = { 0.01f, 0, 0, 0.012f, 0, 0, 0.01f, 0.002f, 0.001f };
                memcpy(t + 9 * m, same, sizeof same);
            } else {
                float e = ldexpf(1.0f, -(int)(m % 10));   /* geometric spacing: 1, 1/2, ..., 1/512 */
                float c[3] = { e, e * 0.5f, -e };
                for (int v = 0; v < 3; v++)
                    for (int a = 0; a < 3; a++) t[9 * m + 3 * v + a] = c[a] + e * rnd_in(r, -0.3f, 0.3f);
            }
        }
    } else {
        /* Long thin slivers crossing the whole scene, whose boxes overlap everything. */
        for (; m < n; m++) {
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) t[9 * m + 3 * v + a] = rnd_in(r, -10, 10);
            for (int a = 0; a < 3; a++) t[9 * m + 6 + a] = t[9 * m + 3 + a] + rnd_in(r, -0.01f, 0.01f);
        }
    }
    *out_n = m;
    return t;
}

/* Brute force closest hit over the source soup: returns the source index or -1; *t the distance. */
static long brute_closest(const float *soup, size_t n, const ms_ray *r, float *t_out)
{
    long best = -1;
    float bt = r->tmax;
    for (size_t i = 0; i < n; i++) {
        float t, u, v;
        if (ms_intersect_triangle(soup + 9 * i, r->o, r->d, r->tmin, bt, &t, &u, &v)) { best = (long)i; bt = t; }
    }
    *t_out = bt;
    return best;
}

static int brute_any(const float *soup, size_t n, const ms_ray *r, long skip_src)
{
    for (size_t i = 0; i < n; i++) {
        float t, u, v;
        if ((long)i != skip_src && ms_intersect_triangle(soup + 9 * i, r->o, r->d, r->tmin, r->tmax, &t, &u, &v)) return 1;
    }
    return 0;
}

/* Structural checks: tri_source is a permutation, leaf triangles are bitwise the source triangles,
 * every node's box contains its subtree, and the depth fits the traversal stack. */
static void check_structure(const ms_bvh *b, const float *soup, size_t n)
{
    assert_int_equal(b->n_tris, n);
    assert_true(b->depth < MS_BVH_STACK);
    char *seen = calloc(n, 1);
    for (uint32_t i = 0; i < b->n_tris; i++) {
        uint32_t s = b->tri_source[i];
        assert_true(s < n);
        assert_false(seen[s]);
        seen[s] = 1;
        assert_memory_equal(b->tri + 9 * (size_t)i, soup + 9 * (size_t)s, 9 * sizeof(float));
    }
    free(seen);
    /* Walk from the root, checking child boxes are inside parents and leaves cover every triangle once. */
    uint32_t stack[256];
    int sp = 0;
    stack[sp++] = 0;
    uint64_t covered = 0;
    while (sp) {
        const ms_bvh_node *nd = &b->nodes[stack[--sp]];
        if (nd->count) {
            covered += nd->count;
            for (uint32_t i = nd->first; i < nd->first + nd->count; i++)
                for (int v = 0; v < 3; v++)
                    for (int a = 0; a < 3; a++) {
                        float x = b->tri[9 * (size_t)i + 3 * v + a];
                        assert_true(x >= nd->bmin[a] && x <= nd->bmax[a]);
                    }
        } else {
            assert_true(nd->first + 1 < b->n_nodes);
            for (int c = 0; c < 2; c++) {
                const ms_bvh_node *ch = &b->nodes[nd->first + c];
                for (int a = 0; a < 3; a++) assert_true(ch->bmin[a] >= nd->bmin[a] && ch->bmax[a] <= nd->bmax[a]);
                assert_true(sp < 256);
                stack[sp++] = nd->first + (uint32_t)c;
            }
        }
    }
    assert_int_equal(covered, n);
}

typedef struct counts { long rays, closest_hits, any_hits, bad_closest, bad_any; } counts;
static int g_verbose = 3;   /* print the first few mismatches in full */

/* One ray through both traversals and both oracles. */
static void check_ray(const ms_bvh *b, const float *soup, size_t n, const ms_ray *r, tu_rng *g, counts *c,
                      const char *what)
{
    float bt;
    long bi = brute_closest(soup, n, r, &bt);
    ms_ray_hit h;
    int got = ms_bvh_closest(b, r, &h);
    if (got != (bi >= 0) || (got && h.t != bt)) {
        c->bad_closest++;
        if (g_verbose-- > 0) print_message("%s: closest o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) [%g,%g]: bvh %d t=%.9g, brute %ld t=%.9g\n", what,
                 r->o[0], r->o[1], r->o[2], r->d[0], r->d[1], r->d[2], r->tmin, r->tmax, got, got ? h.t : 0.0f,
                 bi, bi >= 0 ? bt : 0.0f);
    }
    if (got) {
        /* The reported triangle really is hit at the reported t (ties between triangles may name either). */
        assert_true(h.prim < b->n_tris);
        float t, u, v;
        assert_true(ms_intersect_triangle(b->tri + 9 * (size_t)h.prim, r->o, r->d, r->tmin, r->tmax, &t, &u, &v));
        assert_true(t == h.t);
        assert_true(u == h.u && v == h.v);
        c->closest_hits++;
    } else {
        assert_int_equal(h.prim, UINT32_MAX);
    }
    /* Any-hit: with no skip, with the closest triangle skipped, and with a random triangle skipped. */
    uint32_t skips[3] = { UINT32_MAX, got ? h.prim : UINT32_MAX, (uint32_t)(tu_rng_next(g) % n) };
    for (int k = 0; k < 3; k++) {
        long src = skips[k] == UINT32_MAX ? -1 : (long)b->tri_source[skips[k]];
        int want = brute_any(soup, n, r, src);
        int occ = ms_bvh_occluded(b, r, skips[k]);
        if (occ != want && (c->bad_any++, g_verbose-- > 0))
            print_message("%s: occluded o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) [%g,%g] skip %u: bvh %d, brute %d\n", what,
                     r->o[0], r->o[1], r->o[2], r->d[0], r->d[1], r->d[2], r->tmin, r->tmax, skips[k], occ, want);
        c->any_hits += want;
    }
    c->rays++;
}

static void random_dir(tu_rng *g, float d[3])
{
    do {
        for (int a = 0; a < 3; a++) d[a] = rnd_in(g, -1, 1);
    } while (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < 0.01f);
}

/* nrays rays of six kinds aimed at the soup's triangles, through b and brute force over the soup. */
static void run_rays(const ms_bvh *b, const float *soup, size_t m, tu_rng *gp, int nrays, int kind)
{
    tu_rng g = *gp;
    counts cs[6];
    memset(cs, 0, sizeof cs);
    for (int i = 0; i < nrays; i++) {
        ms_ray r;
        const float *tri = soup + 9 * (tu_rng_next(&g) % m);
        int v0 = (int)(tu_rng_next(&g) % 3), v1 = (v0 + 1) % 3;
        int type = i % 6;
        r.tmin = 0.0f;
        r.tmax = INFINITY;
        switch (type) {
        case 0:   /* random origin, random direction */
            for (int a = 0; a < 3; a++) r.o[a] = rnd_in(&g, -15, 15);
            random_dir(&g, r.d);
            break;
        case 1:   /* from outside towards a vertex of a random triangle */
            for (int a = 0; a < 3; a++) { r.o[a] = rnd_in(&g, -15, 15); r.d[a] = tri[3 * v0 + a] - r.o[a]; }
            break;
        case 2:   /* along an edge: origin on the edge's line before it, direction along the edge */
            for (int a = 0; a < 3; a++) {
                float e = tri[3 * v1 + a] - tri[3 * v0 + a];
                r.o[a] = tri[3 * v0 + a] - 0.5f * e;
                r.d[a] = e;
            }
            break;
        case 3:   /* axis-parallel through a vertex (infinite inverse directions in the slab test) */
            for (int a = 0; a < 3; a++) { r.o[a] = tri[3 * v0 + a]; r.d[a] = 0.0f; }
            {
                int ax = (int)(tu_rng_next(&g) % 3);
                r.o[ax] -= 20.0f;
                r.d[ax] = 1.0f;
            }
            break;
        case 4:   /* finite segment between two random points (shadow-ray style) */
            for (int a = 0; a < 3; a++) { r.o[a] = rnd_in(&g, -12, 12); r.d[a] = rnd_in(&g, -12, 12) - r.o[a]; }
            r.tmin = 1e-4f;
            r.tmax = 1.0f - 1e-4f;
            break;
        default:  /* through the midpoint of an edge, from a random point, with a random tmax */
            for (int a = 0; a < 3; a++) {
                r.o[a] = rnd_in(&g, -15, 15);
                r.d[a] = 0.5f * (tri[3 * v0 + a] + tri[3 * v1 + a]) - r.o[a];
            }
            r.tmax = rnd_in(&g, 0.5f, 1.5f);
            break;
        }
        if (r.d[0] == 0 && r.d[1] == 0 && r.d[2] == 0) continue;
        char what[64];
        snprintf(what, sizeof what, "soup kind %d, ray %d (type %d)", kind, i, type);
        check_ray(b, soup, m, &r, &g, &cs[type], what);
    }
    counts c = { 0, 0, 0, 0, 0 };
    static const char *const type_name[6] = { "random", "to a vertex", "along an edge", "axis-parallel through a vertex",
                                               "segment", "through an edge midpoint" };
    for (int t = 0; t < 6; t++) {
        if (cs[t].bad_closest || cs[t].bad_any)
            print_message("soup kind %d (%zu triangles), rays %s: %ld of %ld disagree with brute force on the closest hit, "
                          "%ld of %ld any-hit queries disagree\n", kind, m, type_name[t], cs[t].bad_closest, cs[t].rays,
                          cs[t].bad_any, 3 * cs[t].rays);
        c.rays += cs[t].rays; c.closest_hits += cs[t].closest_hits; c.any_hits += cs[t].any_hits;
        c.bad_closest += cs[t].bad_closest; c.bad_any += cs[t].bad_any;
    }
    assert_int_equal(c.bad_closest, 0);
    assert_int_equal(c.bad_any, 0);
    /* The rays must actually exercise both answers, or the comparison proves little. */
    assert_true(c.rays > nrays * 9 / 10);
    assert_true(c.closest_hits > c.rays / 10);
    assert_true(c.closest_hits < c.rays);
    *gp = g;
}

static void run_soup(int kind, size_t n, uint64_t seed, int nrays)
{
    tu_rng g = { seed };
    size_t m;
    float *soup = make_soup(kind, n, &g, &m);
    ms_bvh b;
    assert_int_equal(ms_bvh_build(&b, soup, m, 0), 0);
    check_structure(&b, soup, m);
    run_rays(&b, soup, m, &g, nrays, kind);
    ms_bvh_free(&b);
    free(soup);
}

/* Leaves of nd's subtree; every box is asserted to be exactly its contents' (leaves: their triangles' vertices;
 * interior nodes: the union of their children's), i.e. refitted, not the source's. */
static uint32_t check_tight(const ms_bvh *b, uint32_t ni, float lo[3], float hi[3])
{
    const ms_bvh_node *nd = &b->nodes[ni];
    uint32_t leaves = 1;
    for (int a = 0; a < 3; a++) { lo[a] = INFINITY; hi[a] = -INFINITY; }
    if (nd->count) {
        for (uint32_t i = nd->first; i < nd->first + nd->count; i++)
            for (int v = 0; v < 3; v++)
                for (int a = 0; a < 3; a++) {
                    lo[a] = fminf(lo[a], b->tri[9 * (size_t)i + 3 * v + a]);
                    hi[a] = fmaxf(hi[a], b->tri[9 * (size_t)i + 3 * v + a]);
                }
    } else {
        float l2[3], h2[3];
        leaves = check_tight(b, nd->first, lo, hi) + check_tight(b, nd->first + 1, l2, h2);
        for (int a = 0; a < 3; a++) { lo[a] = fminf(lo[a], l2[a]); hi[a] = fmaxf(hi[a], h2[a]); }
    }
    for (int a = 0; a < 3; a++) assert_true(nd->bmin[a] == lo[a] && nd->bmax[a] == hi[a]);
    return leaves;
}

/* ms_bvh_filter: the kept triangles of a built BVH (every other one at random, one half-space of the soup as a
 * cull keeps one side of a solid, all but one, a single one) against brute force over the kept soup; the tree is
 * the source's pruned (no more nodes than a binary tree over its leaves needs, boxes refitted, the kept
 * triangles in the source's order). */
static void run_filtered(int kind, size_t n, uint64_t seed, int nrays)
{
    tu_rng g = { seed };
    size_t m;
    float *soup = make_soup(kind, n, &g, &m);
    ms_bvh b;
    assert_int_equal(ms_bvh_build(&b, soup, m, 0), 0);
    uint8_t *keep = malloc(m);
    float *kept_soup = malloc(9 * m * sizeof(float));
    float xlo = INFINITY, xhi = -INFINITY;   /* the soup's extent along x, for the half-space */
    for (size_t i = 0; i < 3 * m; i++) { xlo = fminf(xlo, soup[3 * i]); xhi = fmaxf(xhi, soup[3 * i]); }
    for (int mode = 0; mode < 4; mode++) {
        size_t nk = 0;
        for (uint32_t i = 0; i < b.n_tris; i++) {
            const float *t = b.tri + 9 * (size_t)i;
            keep[i] = mode == 0 ? (uint8_t)(tu_rng_next(&g) & 1) : mode == 1 ? t[0] + t[3] + t[6] < 1.5f * (xlo + xhi)
                    : mode == 2 ? i != b.n_tris / 2 : i == b.n_tris / 3;
            nk += keep[i];
        }
        ms_bvh f;
        assert_int_equal(ms_bvh_filter(&f, &b, keep), 0);
        /* The kept triangles in source leaf order, and f's tri_source renumbered to index them. */
        uint32_t *rank = malloc(m * sizeof *rank);
        size_t r = 0;
        for (uint32_t i = 0; i < b.n_tris; i++)
            if (keep[i]) { rank[i] = (uint32_t)r; memcpy(kept_soup + 9 * r++, b.tri + 9 * (size_t)i, 9 * sizeof(float)); }
        for (uint32_t i = 0; i < f.n_tris; i++) {
            assert_true(f.tri_source[i] < b.n_tris && keep[f.tri_source[i]]);
            assert_true(i == 0 || f.tri_source[i] > f.tri_source[i - 1]);   /* the source's order */
            assert_memory_equal(f.tri_n + 3 * (size_t)i, b.tri_n + 3 * (size_t)f.tri_source[i], 3 * sizeof(float));
            f.tri_source[i] = rank[f.tri_source[i]];
        }
        check_structure(&f, kept_soup, nk);
        float lo[3], hi[3];
        assert_int_equal(f.n_nodes, 2 * check_tight(&f, 0, lo, hi) - 1);
        if (nk > 1) run_rays(&f, kept_soup, nk, &g, nrays, kind);
        free(rank);
        ms_bvh_free(&f);
    }
    memset(keep, 0, m);
    ms_bvh f;
    assert_int_equal(ms_bvh_filter(&f, &b, keep), -1);   /* nothing kept */
    free(keep);
    free(kept_soup);
    ms_bvh_free(&b);
    free(soup);
}

static void test_filtered(void **st)
{
    (void)st;
    run_filtered(SOUP_RANDOM, 3000, 11, 1500);
    run_filtered(SOUP_GRID, 10000, 12, 1500);
    run_filtered(SOUP_CLUSTER, 3000, 13, 800);
}

static void test_random_soups(void **st)
{
    (void)st;
    run_soup(SOUP_RANDOM, 1500, 1, 3000);
    run_soup(SOUP_RANDOM, 37, 2, 2000);
    run_soup(SOUP_RANDOM, 1, 3, 500);
    run_soup(SOUP_RANDOM, 5000, 4, 1500);
}

static void test_axis_aligned_grid(void **st)
{
    (void)st;
    run_soup(SOUP_GRID, 10000, 5, 4000);
}

/* Rays through every shared vertex and along every shared edge of the axis-aligned grid, from
 * directions in and out of the plane: the cases where hits land exactly on box faces. */
static void test_grid_edges_and_vertices(void **st)
{
    (void)st;
    tu_rng g = { 6 };
    size_t m;
    float *soup = make_soup(SOUP_GRID, 10000, &g, &m);
    ms_bvh b;
    assert_int_equal(ms_bvh_build(&b, soup, m, 0), 0);
    counts c = { 0, 0, 0, 0, 0 };
    for (int i = -6; i <= 6; i++)
        for (int j = -6; j <= 6; j++) {
            float vtx[3] = { (float)i, 0.0f, (float)j };
            const float origins[5][3] = { { 0.3f, 5, 0.7f }, { -7, 4, 2 }, { 2, -3, -9 }, { (float)i, 7, (float)j }, { -20, 0, (float)j } };
            for (int o = 0; o < 5; o++) {
                ms_ray r;
                for (int a = 0; a < 3; a++) { r.o[a] = origins[o][a]; r.d[a] = vtx[a] - r.o[a]; }
                if (r.d[0] == 0 && r.d[1] == 0 && r.d[2] == 0) continue;
                r.tmin = 0.0f;
                r.tmax = INFINITY;
                check_ray(&b, soup, m, &r, &g, &c, "grid vertex");
                r.tmax = 1.0f;   /* segment ending exactly on the vertex */
                check_ray(&b, soup, m, &r, &g, &c, "grid vertex segment");
            }
            /* In the plane y = 0, along the grid line z = j and x = i (grazing the edges). */
            ms_ray r = { { -20.0f, 0.0f, (float)j }, { 1.0f, 0.0f, 0.0f }, 0.0f, INFINITY };
            check_ray(&b, soup, m, &r, &g, &c, "grid edge x");
            ms_ray r2 = { { (float)i, 0.0f, -20.0f }, { 0.0f, 0.0f, 1.0f }, 0.0f, INFINITY };
            check_ray(&b, soup, m, &r2, &g, &c, "grid edge z");
            /* Diagonal in the plane: along the quads' shared diagonals. */
            ms_ray r3 = { { (float)i - 10.0f, 0.0f, (float)j - 10.0f }, { 1.0f, 0.0f, 1.0f }, 0.0f, INFINITY };
            check_ray(&b, soup, m, &r3, &g, &c, "grid diagonal");
        }
    if (c.bad_closest || c.bad_any)
        print_message("axis-aligned grid, rays through its vertices and along its edges: %ld of %ld disagree with brute "
                      "force on the closest hit, %ld of %ld any-hit queries disagree\n", c.bad_closest, c.rays, c.bad_any,
                      3 * c.rays);
    assert_int_equal(c.bad_closest, 0);
    assert_int_equal(c.bad_any, 0);
    assert_true(c.closest_hits > 100);
    ms_bvh_free(&b);
    free(soup);
}

static void test_cluster_and_slivers(void **st)
{
    (void)st;
    run_soup(SOUP_CLUSTER, 6000, 7, 2000);
    run_soup(SOUP_LONG, 800, 8, 2000);
}

/* ms_intersect_triangle against an independent double-precision test (plane intersection and
 * barycentric signs), on rays whose hit is not within a small margin of an edge or of t range ends. */
static void test_triangle_oracle(void **st)
{
    (void)st;
    tu_rng g = { 9 };
    int hits = 0, misses = 0;
    for (int it = 0; it < 20000; it++) {
        float tri[9], o[3], d[3];
        for (int k = 0; k < 9; k++) tri[k] = rnd_in(&g, -2, 2);
        for (int a = 0; a < 3; a++) o[a] = rnd_in(&g, -4, 4);
        /* Aim at a point of the triangle's plane with barycentrics in [-0.4, 1.4]: about half hit. */
        float b1 = rnd_in(&g, -0.4f, 1.4f), b2 = rnd_in(&g, -0.4f, 1.4f) * (1.0f - b1);
        for (int a = 0; a < 3; a++)
            d[a] = tri[a] + b1 * (tri[3 + a] - tri[a]) + b2 * (tri[6 + a] - tri[a]) - o[a];
        if (it % 4 == 0) for (int a = 0; a < 3; a++) d[a] = -d[a];   /* some point away: t < 0 */
        double e1[3], e2[3], nrm[3];
        for (int a = 0; a < 3; a++) { e1[a] = (double)tri[3 + a] - tri[a]; e2[a] = (double)tri[6 + a] - tri[a]; }
        nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double nn = nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2];
        double dn = nrm[0] * d[0] + nrm[1] * d[1] + nrm[2] * d[2];
        double dl = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
        if (nn < 1e-4 || fabs(dn) < 0.05 * sqrt(nn) * dl || dl < 1e-3) continue;   /* skip slivers and grazing rays */
        double t = (nrm[0] * (tri[0] - (double)o[0]) + nrm[1] * (tri[1] - (double)o[1]) + nrm[2] * (tri[2] - (double)o[2])) / dn;
        double p[3], w[3];
        for (int a = 0; a < 3; a++) p[a] = o[a] + t * d[a];
        /* Barycentrics by signed sub-areas along the normal. */
        for (int k = 0; k < 3; k++) {
            const float *A = tri + 3 * ((k + 1) % 3), *B = tri + 3 * ((k + 2) % 3);
            double ab[3], ap[3], cr[3];
            for (int a = 0; a < 3; a++) { ab[a] = (double)B[a] - A[a]; ap[a] = p[a] - A[a]; }
            cr[0] = ab[1] * ap[2] - ab[2] * ap[1];
            cr[1] = ab[2] * ap[0] - ab[0] * ap[2];
            cr[2] = ab[0] * ap[1] - ab[1] * ap[0];
            w[k] = (cr[0] * nrm[0] + cr[1] * nrm[1] + cr[2] * nrm[2]) / nn;
        }
        double margin = 1e-3;
        if (fabs(w[0]) < margin || fabs(w[1]) < margin || fabs(w[2]) < margin || fabs(t) < 1e-3) continue;
        int want = w[0] > 0 && w[1] > 0 && w[2] > 0 && t > 0;
        float ft, fu, fv;
        int got = ms_intersect_triangle(tri, o, d, 0.0f, INFINITY, &ft, &fu, &fv);
        assert_int_equal(got, want);
        if (got) {
            assert_true(fabs(ft - t) <= 1e-4 * (1 + fabs(t)));
            /* u, v are the barycentric weights of vertices 1 and 2. */
            assert_true(fabs(fu - w[1]) < 1e-4 && fabs(fv - w[2]) < 1e-4);
            hits++;
            /* The [tmin, tmax] window: just outside either end is a miss. */
            assert_false(ms_intersect_triangle(tri, o, d, 0.0f, (float)t * 0.99f, &ft, &fu, &fv));
            assert_false(ms_intersect_triangle(tri, o, d, (float)t * 1.01f, INFINITY, &ft, &fu, &fv));
        } else {
            misses++;
        }
    }
    print_message("triangle oracle: %d hits, %d misses compared\n", hits, misses);
    assert_true(hits > 1000 && misses > 1000);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_oracle),
        cmocka_unit_test(test_random_soups),
        cmocka_unit_test(test_axis_aligned_grid),
        cmocka_unit_test(test_grid_edges_and_vertices),
        cmocka_unit_test(test_cluster_and_slivers),
        cmocka_unit_test(test_filtered),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
