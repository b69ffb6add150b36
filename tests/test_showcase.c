/* The CLI's built-in scene (ms_scene_showcase): what it is meant to show is there and valid (per-vertex
 * normals, a textured ground, a metal and rough plastics, alpha-tested cards, a rect, a disk and a sphere
 * light of different colours), and each light has lit (V = 1), penumbra (0 < V < 1) and umbra pixels (V = 0
 * with samples in front, so occluded rather than facing away), by raytrace and by the CLI's default method
 * alike (the same V sample for sample). */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static void test_contents(void **st)
{
    (void)st;
    ms_scene sc;
    char err[512];
    assert_int_equal(ms_scene_showcase(&sc), 0);
    if (ms_scene_validate(&sc, "showcase", err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(sc.n_lights, 3);
    int shapes = 0;
    for (size_t l = 0; l < sc.n_lights; l++) shapes |= 1 << sc.lights[l].shape;
    assert_int_equal(shapes, (1 << MS_LIGHT_RECT) | (1 << MS_LIGHT_DISK) | (1 << MS_LIGHT_SPHERE));
    for (size_t a = 0; a < sc.n_lights; a++)   /* different colours: the chromaticities differ */
        for (size_t b = a + 1; b < sc.n_lights; b++) {
            const ms_vec3 x = sc.lights[a].emission, y = sc.lights[b].emission;
            const double sx = x.x + x.y + x.z, sy = y.x + y.y + y.z;
            assert_true(fabs(x.x / sx - y.x / sy) + fabs(x.z / sx - y.z / sy) > 0.05);
        }
    size_t smooth = 0, textured = 0, metal = 0, rough = 0, alpha = 0;
    for (size_t t = 0; t < sc.n_tris; t++) {
        const float *n = sc.tri_normal ? sc.tri_normal + 9 * t : NULL;
        if (n && !isnan(n[0]) && (n[0] != n[3] || n[1] != n[4] || n[2] != n[5])) smooth++;
        if (!sc.tri_material || sc.tri_material[t] == MS_NO_MATERIAL) continue;
        const ms_material *m = &sc.materials[sc.tri_material[t]];
        textured += m->base_color_texture >= 0 && m->alpha_mode == MS_ALPHA_OPAQUE;
        metal += m->metallic == 1.0f;
        rough += m->metallic == 0.0f && m->roughness >= 0.5f && m->base_color_texture < 0;
        alpha += m->alpha_mode == MS_ALPHA_MASK;
    }
    assert_true(smooth > 1000 && textured >= 2 && metal > 100 && rough > 100 && alpha >= 8);
    ms_scene_free(&sc);
}

/* Per light: lit, penumbra and umbra pixel counts of frame f. */
static void census(const ms_frame *f, size_t l, long *lit, long *pen, long *umbra)
{
    const size_t n = (size_t)f->width * f->height;
    const float *v = f->vis + l * n;
    const uint16_t *fr = f->front + l * n;
    *lit = *pen = *umbra = 0;
    for (size_t i = 0; i < n; i++) {
        if (v[i] < 0.0f || !fr[i]) continue;
        *lit += v[i] == 1.0f;
        *pen += v[i] > 0.0f && v[i] < 1.0f;
        *umbra += v[i] == 0.0f;
    }
}

static void test_light_regions(void **st)
{
    (void)st;
    ms_scene sc;
    assert_int_equal(ms_scene_showcase(&sc), 0);
    const char *const methods[] = { "raytrace", MS_DEFAULT_METHOD };
    ms_frame f[2];
    for (int m = 0; m < 2; m++) {
        ms_render_options o;
        tu_render_options_default(&o);
        o.method = methods[m];
        o.width = 96;
        o.height = 64;
        o.threads = 2;
        tu_render_ok(&sc, &o, &f[m]);
    }
    const long n = 96 * 64;
    for (size_t l = 0; l < sc.n_lights; l++) {
        long lit, pen, umbra;
        census(&f[0], l, &lit, &pen, &umbra);
        fprintf(stderr, "light %zu: %ld lit, %ld penumbra, %ld umbra of %ld pixels\n", l, lit, pen, umbra, n);
        assert_true(lit > n / 20 && pen > n / 50 && umbra > n / 500);
    }
    const tu_agreement a = tu_compare_frames(&f[1], &f[0]);   /* light 0's planes (the rect) */
    assert_int_equal(a.miss_mismatch, 0);
    assert_int_equal(a.beyond_one, 0);
    /* The picture is coloured (not grey: the lights and materials differ). */
    long coloured = 0;
    for (long i = 0; i < n; i++) {
        const float *c = f[0].rgb + 3 * i;
        coloured += fabsf(c[0] - c[2]) > 0.1f * (c[0] + c[2]);
    }
    assert_true(coloured > n / 10);
    ms_frame_free(&f[0]);
    ms_frame_free(&f[1]);
    ms_scene_free(&sc);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = { cmocka_unit_test(test_contents), cmocka_unit_test(test_light_regions) };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
