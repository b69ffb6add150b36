/* Camera conventions: pixel (x,y), y = 0 the top row, rays through pixel centres, right-handed basis;
 * checked on hand-computed values, by round trips, and end to end through the CLI and a PFM whose rows
 * are stored bottom to top. */
#include "testutil.h"
#include "camera/camera.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NEAR(a, b) assert_true(fabs((double)(a) - (double)(b)) < 1e-5)

static void test_hand_computed(void **st)
{
    (void)st;
    /* Looking down -z from the origin, fov 90 (tan = 1), 4x2 pixels (aspect 2). */
    ms_camera c = { { 0, 0, 0 }, { 0, 0, -1 }, { 0, 1, 0 }, 90.0f, 4, 2, MS_CAMERA_PINHOLE, 0, 0 };
    ms_camera_basis b;
    assert_int_equal(ms_camera_basis_init(&b, &c, 4, 2), 0);
    NEAR(b.forward[0], 0); NEAR(b.forward[1], 0); NEAR(b.forward[2], -1);
    NEAR(b.right[0], 1); NEAR(b.right[1], 0); NEAR(b.right[2], 0);   /* cross(forward, up) = +x */
    NEAR(b.up[0], 0); NEAR(b.up[1], 1); NEAR(b.up[2], 0);
    float d[3], o0[3];
    /* Pixel (0,0), the top-left: sx = (2*0.5/4 - 1) * 1 * 2 = -1.5, sy = (1 - 2*0.5/2) = 0.5. */
    ms_camera_ray(&b, 0, 0, o0, d);
    NEAR(d[0], -1.5); NEAR(d[1], 0.5); NEAR(d[2], -1);
    /* Pixel (3,1), the bottom-right: sx = (2*3.5/4 - 1) * 2 = 1.5, sy = 1 - 2*1.5/2 = -0.5. */
    ms_camera_ray(&b, 3, 1, o0, d);
    NEAR(d[0], 1.5); NEAR(d[1], -0.5); NEAR(d[2], -1);
    /* (1, 0.5, -2): sx = 1 / (2 * 1 * 2) = 0.25 -> px = 0.5 * 1.25 * 4 = 2.5;
     * sy = 0.5 / 2 = 0.25 -> py = 0.5 * 0.75 * 2 = 0.75. */
    float p[3] = { 1, 0.5f, -2 }, px, py;
    assert_int_equal(ms_camera_project(&b, p, &px, &py), 0);
    NEAR(px, 2.5); NEAR(py, 0.75);
    float behind[3] = { 0, 0, 1 };
    assert_int_equal(ms_camera_project(&b, behind, &px, &py), -1);

    /* The Quad camera: eye (0,10,12) looking at the origin; the target projects to the image centre and
     * a point on the +x side to the right half, one higher up (+y) to a smaller row. */
    ms_camera q = { { 0, 10, 12 }, { 0, 0, 0 }, { 0, 1, 0 }, 60.0f, 64, 48, MS_CAMERA_PINHOLE, 0, 0 };
    assert_int_equal(ms_camera_basis_init(&b, &q, 64, 48), 0);
    float o[3] = { 0, 0, 0 };
    assert_int_equal(ms_camera_project(&b, o, &px, &py), 0);
    NEAR(px, 32); NEAR(py, 24);
    float xr[3] = { 1, 0, 0 }, yu[3] = { 0, 1, 0 };
    assert_int_equal(ms_camera_project(&b, xr, &px, &py), 0);
    assert_true(px > 32.5f); NEAR(py, 24);
    assert_int_equal(ms_camera_project(&b, yu, &px, &py), 0);
    NEAR(px, 32); assert_true(py < 23.5f);
}

static void test_round_trip(void **st)
{
    (void)st;
    uint32_t h = 1;
    for (int it = 0; it < 200; it++) {
        float r[10];
        for (int k = 0; k < 10; k++) { h = h * 1664525u + 1013904223u; r[k] = (float)(h >> 8) / 16777216.0f; }
        ms_camera c = { { 20 * r[0] - 10, 20 * r[1] - 10, 20 * r[2] - 10 }, { 4 * r[3] - 2, 4 * r[4] - 2, 4 * r[5] - 2 },
                        { 0, 1, 0 }, 10 + 150 * r[6], 1 + (int)(300 * r[7]), 1 + (int)(300 * r[8]), MS_CAMERA_PINHOLE, 0, 0 };
        ms_camera_basis b;
        if (ms_camera_basis_init(&b, &c, c.width, c.height)) continue;
        /* The basis is orthogonal. */
        NEAR(b.forward[0] * b.right[0] + b.forward[1] * b.right[1] + b.forward[2] * b.right[2], 0);
        NEAR(b.up[0] * b.right[0] + b.up[1] * b.right[1] + b.up[2] * b.right[2], 0);
        for (int y = 0; y < c.height; y += 1 + c.height / 7)
            for (int x = 0; x < c.width; x += 1 + c.width / 7) {
                float o[3], d[3], p[3], px, py;
                ms_camera_ray(&b, x, y, o, d);
                for (int a = 0; a < 3; a++) p[a] = b.eye[a] + (1 + 5 * r[9]) * d[a];
                assert_int_equal(ms_camera_project(&b, p, &px, &py), 0);
                assert_true(fabsf(px - ((float)x + 0.5f)) < 2e-3f * (1 + c.width / 100.0f));
                assert_true(fabsf(py - ((float)y + 0.5f)) < 2e-3f * (1 + c.height / 100.0f));
            }
    }
}

static void test_degenerate(void **st)
{
    (void)st;
    ms_camera_basis b;
    ms_camera same = { { 1, 2, 3 }, { 1, 2, 3 }, { 0, 1, 0 }, 60, 8, 8, MS_CAMERA_PINHOLE, 0, 0 };
    ms_camera par = { { 0, 5, 0 }, { 0, 0, 0 }, { 0, 1, 0 }, 60, 8, 8, MS_CAMERA_PINHOLE, 0, 0 };     /* up parallel to the view */
    ms_camera zero_up = { { 0, 0, 5 }, { 0, 0, 0 }, { 0, 0, 0 }, 60, 8, 8, MS_CAMERA_PINHOLE, 0, 0 };
    ms_camera fov0 = { { 0, 0, 5 }, { 0, 0, 0 }, { 0, 1, 0 }, 0, 8, 8, MS_CAMERA_PINHOLE, 0, 0 };
    ms_camera fov180 = { { 0, 0, 5 }, { 0, 0, 0 }, { 0, 1, 0 }, 180, 8, 8, MS_CAMERA_PINHOLE, 0, 0 };
    assert_int_equal(ms_camera_basis_init(&b, &same, 8, 8), -1);
    assert_int_equal(ms_camera_basis_init(&b, &par, 8, 8), -1);
    assert_int_equal(ms_camera_basis_init(&b, &zero_up, 8, 8), -1);
    assert_int_equal(ms_camera_basis_init(&b, &fov0, 8, 8), -1);
    assert_int_equal(ms_camera_basis_init(&b, &fov180, 8, 8), -1);
    assert_int_equal(ms_camera_basis_init(&b, &fov180, 0, 8), -1);
}

/* End to end: camera at (0,0,5) looking at the origin, fov 90, 64x32. At depth 5 a pixel is
 * 2*5/32 = 0.3125 wide and tall, and pixel (x,y)'s centre ray meets z = 0 at
 *   X = (2(x+0.5)/64 - 1) * 2 * 5,   Y = (1 - 2(y+0.5)/32) * 5.
 * (40, 8): X = 2.65625, Y = 2.34375.  (5, 27): X = -8.28125, Y = -3.59375.
 * A triangle 0.12 across around each of these points covers that pixel's centre and no other. */
static void test_cli_end_to_end(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("camera_e2e");
    char obj[4096], json[4096], pfm[4096], png[4096], err[512];
    const double cx[2] = { 2.65625, -8.28125 }, cy[2] = { 2.34375, -3.59375 };
    char text[2048];
    int n = 0;
    for (int t = 0; t < 2; t++)
        n += snprintf(text + n, sizeof text - (size_t)n, "v %.6f %.6f 0\nv %.6f %.6f 0\nv %.6f %.6f 0\n",
                      cx[t] - 0.06, cy[t] - 0.05, cx[t] + 0.06, cy[t] - 0.05, cx[t], cy[t] + 0.06);
    snprintf(text + n, sizeof text - (size_t)n, "f 1 2 3\nf 4 5 6\n");
    assert_int_equal(tu_write_file(tu_path(obj, sizeof obj, dir, "tris.obj"), text), 0);
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "scene.json"),
        "{ \"meshes\": [ { \"file\": \"tris.obj\" } ],\n"
        "  \"camera\": { \"eye\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 90,"
        " \"width\": 64, \"height\": 32 },\n"
        "  \"light\": { \"corner\": [-1, -1, 4], \"edge_s\": [0, 2, 0], \"edge_t\": [2, 0, 0] },\n"
        "  \"render\": { \"samples\": 256 } }\n"), 0);
    tu_path(pfm, sizeof pfm, dir, "vis.pfm");
    tu_path(png, sizeof png, dir, "out.png");
    const char *args[] = { json, "--method", "raytrace", "--quiet", "-o", png, "--vis", pfm, NULL };
    int rc = tu_run_cli(args, err, sizeof err);
    if (rc != 0) fail_msg("CLI exit %d: %s", rc, err);

    /* Read the PFM by hand: header, then rows from the bottom (y = H-1) to the top. */
    FILE *f = fopen(pfm, "rb");
    assert_non_null(f);
    char hdr[64];
    int w = 0, h = 0;
    float scale = 0;
    assert_int_equal(fscanf(f, "%2s %d %d %f", hdr, &w, &h, &scale), 4);
    assert_string_equal(hdr, "Pf");
    assert_int_equal(w, 64);
    assert_int_equal(h, 32);
    assert_true(scale < 0);   /* little-endian */
    fgetc(f);
    static float file_rows[32][64];
    assert_int_equal(fread(file_rows, sizeof(float), 64 * 32, f), 64 * 32);
    assert_int_equal(fgetc(f), EOF);
    fclose(f);
    int hits = 0;
    for (int r = 0; r < 32; r++)
        for (int x = 0; x < 64; x++) {
            int y = 31 - r;   /* file row r holds image row 31 - r */
            float v = file_rows[r][x];
            int expect_hit = (x == 40 && y == 8) || (x == 5 && y == 27);
            if (expect_hit) {
                assert_true(v >= 0.0f && v <= 1.0f);
                hits++;
            } else if (v != -1.0f) {
                fail_msg("pixel (%d,%d) (file row %d) has V=%g; only (40,8) and (5,27) should see a triangle", x, y, r, v);
            }
        }
    assert_int_equal(hits, 2);
    /* The light faces the triangles from in front and nothing blocks it. */
    assert_true(file_rows[31 - 8][40] == 1.0f && file_rows[31 - 27][5] == 1.0f);
    /* tu_read_pfm returns top row first. */
    int w2, h2;
    float *top = tu_read_pfm(pfm, &w2, &h2);
    assert_non_null(top);
    assert_true(top[8 * 64 + 40] == 1.0f && top[27 * 64 + 5] == 1.0f && top[0] == -1.0f);
    free(top);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_computed),
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_cli_end_to_end),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
