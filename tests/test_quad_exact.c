/* The Quad scene against its exact visibility.
 *
 * Ground 20x20 at y = 0, occluder 4x4 at y = 2 (centred), light [-1,1]^2 at y = 6. All three are
 * parallel, so from a ground point p the occluder's central projection onto the light plane is again an
 * axis-aligned square: a point q of the occluder maps to p + (q - p) * 6/2, i.e. x' = 3 q.x - 2 p.x, so
 * the occluder [-2,2]^2 projects to [-6 - 2 p.x, 6 - 2 p.x] x [-6 - 2 p.z, 6 - 2 p.z], and
 *     V(p) = 1 - overlap_x * overlap_z / (light area 4).
 * A camera ray that meets the occluder's top first sees V = 1 (nothing lies above it), and one that
 * meets neither quad sees -1. The oracle traces each pixel's camera ray in double precision with the
 * conventions of microshadow.h, independently of src/camera. No pixel is excluded: at 128x128 no pixel
 * centre falls within rounding of an outline, so even the surface each ray hits agrees exactly. */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 128
#define H 128

static void make_quad_scene(ms_scene *s)
{
    static const float quads[2][4][3] = {
        { { -10, 0, -10 }, { 10, 0, -10 }, { 10, 0, 10 }, { -10, 0, 10 } },
        { { -2, 2, -2 }, { 2, 2, -2 }, { 2, 2, 2 }, { -2, 2, 2 } },
    };
    memset(s, 0, sizeof *s);
    s->n_tris = 4;
    s->tri = malloc(4 * 9 * sizeof(float));
    for (int q = 0; q < 2; q++) {
        const int idx[6] = { 0, 2, 1, 0, 3, 2 };
        for (int v = 0; v < 6; v++) memcpy(s->tri + 18 * q + 3 * v, quads[q][idx[v]], 3 * sizeof(float));
    }
    s->camera = (ms_camera){ { 0, 10, 12 }, { 0, 0, 0 }, { 0, 1, 0 }, 60.0f, W, H, MS_CAMERA_PINHOLE, 0, 0 };
    s->light = (ms_light){ { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    s->samples = 1024;
}

static double overlap(double lo, double hi) /* of [lo,hi] with the light's [-1,1] */
{
    double a = lo > -1 ? lo : -1, b = hi < 1 ? hi : 1;
    return b > a ? b - a : 0.0;
}

typedef struct oracle {
    double v[W * H];
    int ground[W * H];    /* 1 where the ray's first hit is the ground */
} oracle;

static void cross(double r[3], const double a[3], const double b[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}
static void normalize(double a[3])
{
    double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int i = 0; i < 3; i++) a[i] /= l;
}

static void compute_oracle(oracle *o)
{
    const double eye[3] = { 0, 10, 12 }, target[3] = { 0, 0, 0 }, up[3] = { 0, 1, 0 };
    double f[3] = { target[0] - eye[0], target[1] - eye[1], target[2] - eye[2] }, r[3], u[3];
    normalize(f);
    cross(r, f, up);
    normalize(r);
    cross(u, r, f);
    const double th = tan(0.5 * 60.0 * M_PI / 180.0), aspect = (double)W / H;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double sx = (2.0 * (x + 0.5) / W - 1.0) * th * aspect, sy = (1.0 - 2.0 * (y + 0.5) / H) * th;
            double d[3];
            for (int a = 0; a < 3; a++) d[a] = f[a] + sx * r[a] + sy * u[a];
            size_t i = (size_t)y * W + x;
            o->ground[i] = 0;
            o->v[i] = -1.0;
            if (d[1] >= 0) continue;
            double t2 = (2.0 - eye[1]) / d[1];
            double qx = eye[0] + t2 * d[0], qz = eye[2] + t2 * d[2];
            if (fabs(qx) <= 2 && fabs(qz) <= 2) { o->v[i] = 1.0; continue; }
            double t0 = (0.0 - eye[1]) / d[1];
            double px = eye[0] + t0 * d[0], pz = eye[2] + t0 * d[2];
            if (fabs(px) > 10 || fabs(pz) > 10) continue;
            double ox = overlap(-6 - 2 * px, 6 - 2 * px), oz = overlap(-6 - 2 * pz, 6 - 2 * pz);
            o->v[i] = 1.0 - ox * oz / 4.0;
            o->ground[i] = 1;
        }
}

static void check_pattern(ms_pattern pat, double mae_max, double max_max)
{
    static oracle o;
    compute_oracle(&o);
    ms_scene s;
    make_quad_scene(&s);
    ms_render_options opt;
    tu_render_options_default(&opt);
    opt.method = "raytrace";
    opt.pattern = pat;
    opt.samples = 1024;
    opt.width = W;
    opt.height = H;
    opt.seed = 7;
    ms_frame fr;
    char err[512];
    assert_int_equal(ms_render(&s, &opt, &fr, err, sizeof err), 0);
    assert_int_equal(fr.width, W);
    assert_int_equal(fr.height, H);
    double sum = 0.0, worst = 0.0;
    int n_ground = 0, n_penumbra = 0, n_umbra = 0, n_occ = 0, n_miss = 0, worst_i = -1;
    for (int i = 0; i < W * H; i++) {
        double got = fr.vis[i];
        if (o.v[i] < 0) {
            /* Misses agree exactly: the ground's outline is far from every pixel centre here. */
            if (got != -1.0f) fail_msg("pixel (%d,%d): oracle misses, render V=%g", i % W, i / W, got);
            n_miss++;
            continue;
        }
        if (!o.ground[i]) {
            /* The occluder's top sees the whole light. */
            if (got != 1.0f) fail_msg("pixel (%d,%d) on the occluder: V=%g, want 1", i % W, i / W, got);
            n_occ++;
            continue;
        }
        double e = fabs(got - o.v[i]);
        sum += e;
        n_ground++;
        n_penumbra += o.v[i] > 0 && o.v[i] < 1;
        n_umbra += o.v[i] == 0;
        if (e > worst) { worst = e; worst_i = i; }
    }
    double mae = sum / n_ground;
    print_message("%s: %d ground pixels (%d penumbra, %d umbra), %d on the occluder, %d misses: MAE %.5f, max %.4f at (%d,%d)\n",
                  pat == MS_PATTERN_GRID ? "grid" : "stratified", n_ground, n_penumbra, n_umbra, n_occ, n_miss, mae,
                  worst, worst_i % W, worst_i / W);
    /* The test must see every kind of pixel. */
    assert_true(n_penumbra > 500 && n_umbra > 50 && n_occ > 50 && n_miss > 50);
    assert_true(mae < mae_max);
    assert_true(worst <= max_max);
    ms_frame_free(&fr);
    ms_scene_free(&s);
}

static void test_quad_grid(void **st) { (void)st; check_pattern(MS_PATTERN_GRID, 0.002, 0.05); }
static void test_quad_stratified(void **st) { (void)st; check_pattern(MS_PATTERN_STRATIFIED, 0.002, 0.05); }

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_quad_grid),
        cmocka_unit_test(test_quad_stratified),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
