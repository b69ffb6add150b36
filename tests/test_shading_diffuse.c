/* ms_render_options.shading = MS_SHADING_DIFFUSE (`--shading diffuse`): the picture a lightmap can give,
 * base colour x E_unshadowed x S / pi per light, with no specular lobe, no metallic darkening and no emission.
 * A floor of two materials (a glossy dielectric; a half-metallic, emissive, glossy one) under a rect light with
 * an occluder: at every floor pixel the diffuse frame equals emission x base x E(p, n) x S / pi, E from
 * ms_light_irradiance at the pixel's own floor point and S the standard frame's (the shading does not change
 * visibility); the standard frame differs from it (specular, metal); the CLI refuses an unknown shading. */
#include "testutil.h"
#include "camera/camera.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double BASE[2][3] = { { 0.7, 0.6, 0.5 }, { 0.3, 0.5, 0.8 } };

static void test_diffuse_against_oracle(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("shading_diffuse");
    char p[1024], json[1024], err[512] = "";
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "m.mtl"),
        "newmtl a\nKd 0.7 0.6 0.5\nPr 0.3\nPm 0\nnewmtl b\nKd 0.3 0.5 0.8\nPr 0.4\nPm 0.5\nKe 0.2 0.1 0\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "floor.obj"),
        "mtllib m.mtl\nv -2 0 -2\nv 0 0 -2\nv 2 0 -2\nv -2 0 2\nv 0 0 2\nv 2 0 2\n"
        "usemtl a\nf 4 5 2\nf 4 2 1\nusemtl b\nf 5 6 3\nf 5 3 2\n"), 0);
    assert_int_equal(tu_write_file(tu_path(p, sizeof p, dir, "plate.obj"),
        "v -0.5 1 -0.3\nv 0.5 1 -0.3\nv 0.5 1 0.3\nv -0.5 1 0.3\nf 1 2 3 4\nf 4 3 2 1\n"), 0);
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "scene.json"),
        "{\"meshes\":[{\"file\":\"floor.obj\"},{\"file\":\"plate.obj\"}],"
        "\"camera\":{\"eye\":[0,4,4],\"target\":[0,0,0],\"up\":[0,1,0],\"fov_y\":50,\"width\":64,\"height\":64},"
        "\"light\":{\"corner\":[-1,3,-1],\"edge_s\":[2,0,0],\"edge_t\":[0,0,2],\"emission\":[3,3,3]}}"), 0);
    ms_scene sc;
    assert_int_equal(ms_scene_load(json, &sc, err, sizeof err), 0);
    ms_render_options ro;
    tu_render_options_default(&ro);
    ro.samples = 256;
    ms_frame fs, fd;
    assert_int_equal(ms_render(&sc, &ro, &fs, err, sizeof err), 0);
    ro.shading = MS_SHADING_DIFFUSE;
    assert_int_equal(ms_render(&sc, &ro, &fd, err, sizeof err), 0);
    ms_camera_basis cb;
    assert_int_equal(ms_camera_basis_init(&cb, &sc.camera, fd.width, fd.height), 0);
    int checked[2] = { 0, 0 }, penumbra = 0;
    double worst = 0.0, differs = 0.0;
    for (int y = 0; y < fd.height; y++)
        for (int x = 0; x < fd.width; x++) {
            float o[3], d[3];
            ms_camera_ray(&cb, x, y, o, d);
            if (!(d[1] < 0)) continue;
            const double t = -cb.eye[1] / d[1];
            const float q[3] = { (float)(cb.eye[0] + t * d[0]), 0.0f, (float)(cb.eye[2] + t * d[2]) };
            /* the floor, away from the materials' border */
            if (fabsf(q[0]) < 0.1f || fabsf(q[0]) > 1.9f || fabsf(q[2]) > 1.9f) continue;
            const size_t i = (size_t)y * fd.width + x;
            const double t1 = (1.0 - cb.eye[1]) / d[1];   /* the plate's plane, y = 1: its pixels are not the floor's */
            if (fabs(cb.eye[0] + t1 * d[0]) < 0.55 && fabs(cb.eye[2] + t1 * d[2]) < 0.35) continue;
            if (!(fd.vis[i] >= 0.0f)) continue;
            assert_true(fd.shadow[i] == fs.shadow[i]);   /* the shading leaves visibility alone */
            const float n[3] = { 0, 1, 0 };
            const double E = ms_light_irradiance(&sc.light, q, n), S = fd.shadow[i];
            if (S > 0.05 && S < 0.95) penumbra++;
            const int m = q[0] > 0;
            for (int c = 0; c < 3; c++) {
                const double want = 3.0 * BASE[m][c] * E * S / M_PI;
                const double e = fabs(fd.rgb[3 * i + c] - want) / (3.0 * E / M_PI);
                worst = fmax(worst, e);
                differs = fmax(differs, fabs(fs.rgb[3 * i + c] - want) / (3.0 * E / M_PI));
            }
            checked[m]++;
        }
    printf("diffuse shading: %d + %d floor pixels (%d in penumbra), worst |rgb - base E S / pi| %.2e of E / pi; the standard "
           "frame differs by up to %.3f; exposure %.5g diffuse, %.5g standard\n", checked[0], checked[1], penumbra, worst,
           differs, (double)fd.exposure, (double)fs.exposure);
    assert_true(checked[0] > 100 && checked[1] > 100 && penumbra > 20);
    assert_true(worst <= 1e-4);   /* the pixel's own hit point against the floor point of the camera ray here */
    assert_true(differs >= 0.05);
    ms_frame_free(&fs);
    ms_frame_free(&fd);
    ms_scene_free(&sc);
    /* the CLI: --shading diffuse runs, an unknown one is refused with exit 2 */
    char out[1024], line[512];
    tu_path(out, sizeof out, dir, "d.png");
    const char *ok[] = { json, "--shading", "diffuse", "--samples", "256", "-o", out, "--quiet", NULL };
    assert_int_equal(tu_run_cli(ok, line, sizeof line), 0);
    assert_true(tu_file_exists(out));
    const char *bad[] = { json, "--shading", "glossy", "-o", out, "--quiet", NULL };
    assert_int_equal(tu_run_cli(bad, line, sizeof line), 2);
    assert_non_null(strstr(line, "--shading: 'glossy' is not standard or diffuse"));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_diffuse_against_oracle),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
