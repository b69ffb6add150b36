/* Holed surfaces capped for the interior boxes (src/accel/holes.c, docs/culling.md "Holes").
 *
 * Caps: a sphere with one hole, two holes, or two holes that touch at a vertex is a holed set, and with its caps
 * every edge is used an even number of times (counted here by a weld of the test's own); small meshes and
 * sheets (a long rim for their size) are left out. ms_cap_hidden against sampled segments: whenever it says a
 * box is hidden from a light behind a cap, no segment from a point sampled in the box to a point sampled on the
 * light meets the cap (double Moller-Trumbore written here), and both answers occur. The boxes a light keeps
 * (the driver's rule, occluders.c): every segment sampled from a kept box to the light meets a real triangle,
 * so it is occluded whatever the receiver; a light that looks into the hole keeps fewer. Frames of a holed
 * sphere over a ground: every method that takes the boxes (scanline by block and by pixel, hierarchical, mft)
 * equals raytrace bit for bit, for a light above (the hole on the side) and one that sees into the hole; so does the
 * points API (a bake's path) on the ground and on every sphere triangle, facing out and in. */
#include "testutil.h"
#include "accel/closed.h"
#include "accel/holes.h"
#include "accel/interior.h"
#include "test_mesh.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The triangles of m whose centroid's axis-a coordinate is within [lo, hi] removed (a hole where that slab cuts
 * the surface). */
static void cut(tm_mesh *m, int a, double lo, double hi)
{
    size_t k = 0;
    for (size_t t = 0; t < m->n; t++) {
        const float *p = m->tri + 9 * t;
        const double c = ((double)p[a] + p[3 + a] + p[6 + a]) / 3.0;
        if (c >= lo && c <= hi) continue;
        memmove(m->tri + 9 * k++, p, 9 * sizeof *p);
    }
    m->n = k;
}

/* ---- caps ---- */

typedef struct corner { float p[3]; uint32_t i; } corner;

static int corner_cmp(const void *a, const void *b)
{
    return memcmp(((const corner *)a)->p, ((const corner *)b)->p, sizeof(float[3]));
}

static int u64_cmp(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The number of undirected edges used an odd number of times by the n triangles tri: vertices welded by their
 * exact coordinates (a sort), edges as pairs of welded vertices (another sort). */
static size_t odd_edges(const float *tri, size_t n)
{
    corner *c = malloc(3 * n * sizeof *c);
    uint32_t *id = malloc(3 * n * sizeof *id);
    uint64_t *e = malloc(3 * n * sizeof *e);
    assert_true(c && id && e);
    for (size_t i = 0; i < 3 * n; i++) {
        memcpy(c[i].p, tri + 3 * i, sizeof c[i].p);
        for (int a = 0; a < 3; a++) c[i].p[a] += 0.0f;
        c[i].i = (uint32_t)i;
    }
    qsort(c, 3 * n, sizeof *c, corner_cmp);
    uint32_t v = 0;
    for (size_t i = 0; i < 3 * n; i++) {
        if (i && corner_cmp(&c[i - 1], &c[i])) v++;
        id[c[i].i] = v;
    }
    size_t ne = 0;
    for (size_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = id[3 * t + (size_t)k], b = id[3 * t + (size_t)(k + 1) % 3];
            if (a == b) continue;
            if (a > b) { const uint64_t x = a; a = b; b = x; }
            e[ne++] = a << 32 | b;
        }
    qsort(e, ne, sizeof *e, u64_cmp);
    size_t odd = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && e[j] == e[i]) j++;
        odd += (j - i) & 1;
        i = j;
    }
    free(c);
    free(id);
    free(e);
    return odd;
}

/* Holed set h's triangles and caps, together. */
static tm_mesh holed_with_caps(const tm_mesh *m, const ms_closed *c, uint32_t h)
{
    tm_mesh o = { 0 };
    for (size_t t = 0; t < m->n; t++)
        if (c->holed[t] == h) {
            const float *p = m->tri + 9 * t;
            const double a[3] = { p[0], p[1], p[2] }, b[3] = { p[3], p[4], p[5] }, d[3] = { p[6], p[7], p[8] };
            tm_add_tri(&o, a, b, d);
        }
    for (size_t i = c->cap_start[h]; i < c->cap_start[h + 1]; i++) {
        const float *p = c->cap + 9 * i;
        const double a[3] = { p[0], p[1], p[2] }, b[3] = { p[3], p[4], p[5] }, d[3] = { p[6], p[7], p[8] };
        tm_add_tri(&o, a, b, d);
    }
    return o;
}

static void test_caps(void **st)
{
    (void)st;
    const double c0[3] = { 0, 0, 0 };
    for (int variant = 0; variant < 3; variant++) {
        tm_mesh m = { 0 };
        tm_icosphere(&m, c0, 1.0, 4, 0, 0.05, 7);
        cut(&m, 1, -2.0, -0.85);                  /* a hole at the bottom */
        if (variant == 1) cut(&m, 1, 0.9, 2.0);   /* and one at the top */
        if (variant == 2) {   /* and a second sphere with a hole at the top: two holed sets */
            const double c1[3] = { 3, 0, 0 };
            tm_mesh o = { 0 };
            tm_icosphere(&o, c1, 1.0, 3, 0, 0.05, 8);
            cut(&o, 1, 0.9, 2.0);
            for (size_t t = 0; t < o.n; t++) {
                const float *p = o.tri + 9 * t;
                const double a[3] = { p[0], p[1], p[2] }, b[3] = { p[3], p[4], p[5] }, d[3] = { p[6], p[7], p[8] };
                tm_add_tri(&m, a, b, d);
            }
            free(o.tri);
        }
        const size_t rim = odd_edges(m.tri, m.n);
        assert_true(rim > 0);
        ms_closed c;
        assert_int_equal(ms_closed_find(m.tri, m.n, &c), 0);
        assert_int_equal(c.n_cycles, 0);
        assert_int_equal(c.n_components, 0);
        assert_int_equal(c.n_holed, variant == 2 ? 2 : 1);
        for (size_t t = 0; t < m.n; t++) assert_true(c.holed[t] < c.n_holed);
        /* one cap per rim edge (a fan per walk), and with them no edge of a set is used an odd number of times */
        assert_int_equal(c.cap_start[c.n_holed] - c.cap_start[0], rim);
        for (uint32_t h = 0; h < c.n_holed; h++) {
            tm_mesh o = holed_with_caps(&m, &c, h);
            assert_int_equal(odd_edges(o.tri, o.n), 0);
            /* the caps within the set's box */
            for (size_t i = 9 * c.cap_start[h]; i < 9 * c.cap_start[h + 1]; i++) {
                const int a = (int)(i % 3);
                assert_true(c.cap[i] >= c.holed_box[h][a] && c.cap[i] <= c.holed_box[h][3 + a]);
            }
            free(o.tri);
        }
        print_message("variant %d: %zu triangles, %zu rim edges, %zu holed sets\n", variant, m.n, rim, c.n_holed);
        ms_closed_free(&c);
        free(m.tri);
    }
    /* left out: fewer than MS_HOLED_MIN_TRIS triangles; a sheet and a shallow bowl (a fifth of a sphere), whose
     * rims are long for their size */
    tm_mesh small = { 0 };
    tm_icosphere(&small, c0, 1.0, 1, 0, 0.0, 0);
    cut(&small, 1, -2.0, -0.7);
    tm_mesh sheet = { 0 };
    for (int i = 0; i < 20; i++)
        for (int j = 0; j < 20; j++) {
            const double a[3] = { i, 0, j }, b[3] = { i + 1, 0, j }, d[3] = { i + 1, 0, j + 1 }, e[3] = { i, 0, j + 1 };
            tm_add_tri(&sheet, a, b, d);
            tm_add_tri(&sheet, a, d, e);
        }
    tm_mesh bowl = { 0 };
    tm_icosphere(&bowl, c0, 1.0, 4, 0, 0.0, 0);
    cut(&bowl, 0, -2.0, 0.6);
    assert_true(bowl.n >= MS_HOLED_MIN_TRIS && sheet.n >= MS_HOLED_MIN_TRIS);
    const tm_mesh *none[3] = { &small, &sheet, &bowl };
    for (int k = 0; k < 3; k++) {
        ms_closed c;
        assert_true(odd_edges(none[k]->tri, none[k]->n) > 0);
        assert_int_equal(ms_closed_find(none[k]->tri, none[k]->n, &c), 0);
        assert_int_equal(c.n_holed, 0);
        assert_int_equal(c.n_cycles, 0);
        ms_closed_free(&c);
    }
    free(small.tri);
    free(sheet.tri);
    free(bowl.tri);
}

/* ---- ms_cap_hidden ---- */

/* A random point of box b, and of the rect light with corners pts (0, 1, 2, 3 = c, c + s, c + t, c + s + t). */
static void box_point(const float b[6], unsigned *s, double p[3])
{
    for (int a = 0; a < 3; a++) p[a] = b[a] + tm_urand(s) * ((double)b[3 + a] - b[a]);
}

static void light_point(const float (*pts)[3], unsigned *s, double p[3])
{
    const double u = tm_urand(s), v = tm_urand(s);
    for (int a = 0; a < 3; a++) p[a] = pts[0][a] + u * ((double)pts[1][a] - pts[0][a]) + v * ((double)pts[2][a] - pts[0][a]);
}

/* Does segment p -> l meet triangle t anywhere (u in [0, 1])? */
static int meets(const float *t, const double p[3], const double l[3])
{
    /* tm_seg_hits's range is the occlusion range; extended by a step either way to cover the whole segment */
    double q[3], r[3];
    for (int a = 0; a < 3; a++) {
        q[a] = p[a] - 1e-3 * (l[a] - p[a]);
        r[a] = l[a] + 1e-3 * (l[a] - p[a]);
    }
    return tm_seg_hits(t, q, r);
}

static void test_cap_hidden_sampled(void **st)
{
    (void)st;
    unsigned s = 12345;
    int hidden = 0, shown = 0, met = 0;
    for (int trial = 0; trial < 400; trial++) {
        float b[6], pts[4][3], cap[9];
        for (int a = 0; a < 3; a++) {
            b[a] = (float)(-1.0 + tm_urand(&s));
            b[3 + a] = b[a] + (float)(0.1 + 0.6 * tm_urand(&s));
        }
        /* a light above, 1.5 to 2.5 wide, and a cap between (or beside) */
        const double lx = -2.0 + 4.0 * tm_urand(&s), lz = -2.0 + 4.0 * tm_urand(&s), w = 1.5 + tm_urand(&s);
        for (int q = 0; q < 4; q++) {
            pts[q][0] = (float)(lx + ((q & 1) ? w : 0.0));
            pts[q][1] = 4.0f;
            pts[q][2] = (float)(lz + ((q & 2) ? w : 0.0));
        }
        const double cy = 0.5 + 2.5 * tm_urand(&s), cx = -1.5 + 3.0 * tm_urand(&s), cz = -1.5 + 3.0 * tm_urand(&s);
        for (int v = 0; v < 3; v++) {
            cap[3 * v] = (float)(cx + 1.2 * (tm_urand(&s) - 0.5));
            cap[3 * v + 1] = (float)(cy + 0.6 * (tm_urand(&s) - 0.5));
            cap[3 * v + 2] = (float)(cz + 1.2 * (tm_urand(&s) - 0.5));
        }
        const float (*pp)[3] = (const float (*)[3])pts;
        const int h = ms_cap_hidden(b, pp, 4, cap, 1e-6);
        hidden += h;
        shown += !h;
        int hit = 0;
        for (int k = 0; k < 3000 && !hit; k++) {
            double p[3], l[3];
            box_point(b, &s, p);
            light_point(pp, &s, l);
            hit = meets(cap, p, l);
        }
        met += hit;
        if (h) assert_false(hit);
    }
    print_message("%d hidden, %d not (%d with a sampled segment through the cap)\n", hidden, shown, met);
    assert_true(hidden > 40 && met > 40);
}

/* ---- the boxes a light keeps ---- */

/* The boxes of `in` the driver keeps for the light pts (occluders.c, box_holds): a holed set's when every cap
 * hides it. */
static int kept(const ms_closed *c, const float b[6], uint32_t comp, const float (*pts)[3], double tol)
{
    if (comp < c->n_cycles) return 1;
    const size_t h = comp - c->n_cycles;
    for (size_t i = c->cap_start[h]; i < c->cap_start[h + 1]; i++)
        if (!ms_cap_hidden(b, pts, 4, c->cap + 9 * i, tol)) return 0;
    return 1;
}

static void test_boxes_exact(void **st)
{
    (void)st;
    tm_mesh m = { 0 };
    const double c0[3] = { 0, 0, 0 };
    tm_icosphere(&m, c0, 1.0, 4, 0, 0.05, 3);
    cut(&m, 0, 0.9, 2.0);   /* a hole on the +x side */
    ms_closed c;
    assert_int_equal(ms_closed_find(m.tri, m.n, &c), 0);
    assert_int_equal(c.n_holed, 1);
    ms_interior in;
    const double eps = 2e-3;
    assert_int_equal(ms_interior_find(m.tri, m.n, &c, 24, 0, eps, 2, &in), 0);
    assert_true(in.n_boxes > 10);
    /* above the sphere, and above the hole's side, where the segments from the boxes near the hole pass it */
    const float above[4][3] = { { -0.5f, 3, -0.5f }, { 0.5f, 3, -0.5f }, { -0.5f, 3, 0.5f }, { 0.5f, 3, 0.5f } };
    const float side[4][3] = { { 1.5f, 2, -0.5f }, { 2.5f, 2, -0.5f }, { 1.5f, 2, 0.5f }, { 2.5f, 2, 0.5f } };
    const float (*lights[2])[3] = { above, side };
    size_t n_kept[2] = { 0, 0 };
    unsigned s = 99;
    for (int l = 0; l < 2; l++) {
        for (size_t b = 0; b < in.n_boxes; b++) {
            if (!kept(&c, in.box[b], in.component[b], lights[l], 1e-6)) continue;
            n_kept[l]++;
            /* every segment from the box to the light crosses the real surface */
            for (int k = 0; k < 200; k++) {
                double p[3], q[3];
                box_point(in.box[b], &s, p);
                light_point(lights[l], &s, q);
                int hit = 0;
                for (size_t t = 0; t < m.n && !hit; t++) hit = tm_seg_hits(m.tri + 9 * t, p, q);
                assert_true(hit);
            }
        }
        print_message("light %d keeps %zu of %zu boxes\n", l, n_kept[l], in.n_boxes);
    }
    assert_true(n_kept[0] > in.n_boxes / 2);
    assert_true(n_kept[1] > 0 && n_kept[1] < n_kept[0]);
    ms_interior_free(&in);
    ms_closed_free(&c);
    free(m.tri);
}

/* ---- frames ---- */

/* The Quad with a ground and a holed sphere (5120 triangles less a cap on the +x side, which the camera sees into)
 * instead of its occluder; the sphere's triangles from index 2 on. */
static void holed_scene(ms_scene *sc)
{
    tu_make_quad(sc);
    tm_mesh m = { 0 };
    tm_ground(&m);
    tm_mesh sphere = { 0 };
    const double c[3] = { 0.3, 1.6, -0.2 };
    tm_icosphere(&sphere, c, 1.2, 4, 0, 0.08, 11);
    cut(&sphere, 0, 0.3 + 0.85 * 1.2, 10.0);
    for (size_t t = 0; t < sphere.n; t++) {
        const float *p = sphere.tri + 9 * t;
        const double a[3] = { p[0], p[1], p[2] }, b[3] = { p[3], p[4], p[5] }, d[3] = { p[6], p[7], p[8] };
        tm_add_tri(&m, a, b, d);
    }
    free(sphere.tri);
    free(sc->tri);
    sc->tri = m.tri;
    sc->n_tris = m.n;
    sc->camera.width = sc->camera.height = 64;
    sc->camera.eye = (ms_vec3){ 4, 4, 4 };
    sc->camera.target = (ms_vec3){ 0, 0.8f, 0 };
}

/* The second light: above the hole's side, so that the boxes near the hole see it through the hole. */
static void light_above_hole(ms_light *l)
{
    l->corner = (ms_vec3){ 2.1f, 3.6f, -0.7f };
    l->edge_s = (ms_vec3){ 1, 0, 0 };
    l->edge_t = (ms_vec3){ 0, 0, 1 };
}

static void test_holed_frames(void **st)
{
    (void)st;
    ms_scene sc;
    holed_scene(&sc);
    const int npix = 64 * 64;
    uint64_t boxes[2];
    for (int light = 0; light < 2; light++) {
        if (light == 1) light_above_hole(&sc.light);
        ms_render_options o;
        tu_render_options_default(&o);
        o.threads = 2;
        ms_stats s_rt;
        o.method = "raytrace";
        float *v_rt = tu_render_vis(&sc, &o, &s_rt);
        int shadowed = 0;
        for (int i = 0; i < npix; i++) shadowed += v_rt[i] >= 0.0f && v_rt[i] < 1.0f;
        assert_true(shadowed > npix / 10);
        assert_int_equal(s_rt.interior_boxes, 0);
        /* the methods that take the boxes: scanline's block and per-pixel traversals, hierarchical, mft */
        static const char *const method[4] = { "scanline", "scanline", "hierarchical", "mft" };
        for (int k = 0; k < 4; k++) {
            ms_stats s;
            o.method = method[k];
            o.traversal = k == 1 ? MS_TRAVERSAL_PIXEL : MS_TRAVERSAL_BLOCK;
            float *v = tu_render_vis(&sc, &o, &s);
            if (k == 0) {
                boxes[light] = s.interior_boxes;
                print_message("light %d: %d shadowed pixels, %llu boxes\n", light, shadowed, (unsigned long long)boxes[light]);
                assert_true(tu_stat_counter(&s, "interior_rasterized") > 0);
            }
            assert_true(s.interior_boxes > 0);
            assert_memory_equal(v, v_rt, npix * sizeof *v);
            free(v);
        }
        free(v_rt);
    }
    assert_true(boxes[1] < boxes[0]);
    ms_scene_free(&sc);
}

/* The points API (a bake's path) with the holed sphere's boxes: raytrace's V point for point, on the ground around
 * the sphere and at the centroid of every sphere triangle, every other one facing inwards (the inside, lit through
 * the hole). */
static void test_holed_points(void **st)
{
    (void)st;
    ms_scene sc;
    holed_scene(&sc);
    ms_accel *acc;
    char err[256];
    assert_int_equal(ms_accel_build(&sc, 2, &acc, err, sizeof err), MS_OK);
    const size_t n_sphere = sc.n_tris - 2, n = n_sphere + 1000;
    float *pos = malloc(n * 3 * sizeof *pos), *nrm = malloc(n * 3 * sizeof *nrm);
    uint32_t *tri = malloc(n * sizeof *tri);
    assert_true(pos && nrm && tri);
    unsigned seed = 5;
    for (size_t i = 0; i < n; i++) {
        if (i >= n_sphere) {
            pos[3 * i] = (float)(-2.7 + 6.0 * tm_urand(&seed));
            pos[3 * i + 1] = 0.0f;
            pos[3 * i + 2] = (float)(-3.2 + 6.0 * tm_urand(&seed));
            nrm[3 * i] = 0.0f; nrm[3 * i + 1] = 1.0f; nrm[3 * i + 2] = 0.0f;
            tri[i] = 0;   /* either ground triangle: both lie in y = 0 */
            continue;
        }
        tm_centroid_normal(sc.tri + 9 * (i + 2), pos + 3 * i, nrm + 3 * i);
        /* every other one facing inwards: the inside seen through the hole, whose segments cross the boxes */
        if (i % 2)
            for (int a = 0; a < 3; a++) nrm[3 * i + (size_t)a] = -nrm[3 * i + (size_t)a];
        tri[i] = (uint32_t)(i + 2);
    }
    const ms_points pts = { n, pos, nrm, tri, NULL };
    float *v_sl = malloc(n * sizeof *v_sl), *v_rt = malloc(n * sizeof *v_rt);
    assert_true(v_sl && v_rt);
    ms_points_options o = { 0 };
    o.threads = 2;
    o.isa = tu_isa_cap();
    for (int light = 0; light < 2; light++) {
        ms_light l = sc.light;
        if (light == 1) light_above_hole(&l);
        ms_stats s_sl;
        o.method = "scanline";
        assert_int_equal(ms_visibility_points(acc, &l, &pts, &o, v_sl, NULL, NULL, &s_sl, err, sizeof err), MS_OK);
        o.method = "raytrace";
        assert_int_equal(ms_visibility_points(acc, &l, &pts, &o, v_rt, NULL, NULL, NULL, err, sizeof err), MS_OK);
        int shadowed = 0;
        for (size_t i = 0; i < n; i++) shadowed += v_rt[i] >= 0.0f && v_rt[i] < 1.0f;
        print_message("points, light %d: %d shadowed, %llu boxes\n", light, shadowed, (unsigned long long)s_sl.interior_boxes);
        assert_true(shadowed > 500);
        assert_true(s_sl.interior_boxes > 0);
        assert_memory_equal(v_sl, v_rt, n * sizeof *v_sl);
    }
    free(v_sl); free(v_rt); free(pos); free(nrm); free(tri);
    ms_accel_free(acc);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_caps),
        cmocka_unit_test(test_cap_hidden_sampled),
        cmocka_unit_test(test_boxes_exact),
        cmocka_unit_test(test_holed_frames),
        cmocka_unit_test(test_holed_points),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
