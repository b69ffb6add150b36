/* An emitter's emissive texture (src/scene/scene_emitters.c): the light made from an emissive glTF quad
 * carries emissiveFactor x the mean of its emissive texture over the shape, in linear RGB. The texture is a
 * 2 x 2 sRGB PNG made here with libpng; the quad's UVs cover it once, so the mean over the shape is the mean
 * of the four texels decoded with the sRGB formula written below (the oracle), and a quad whose UVs cover only
 * the left column means that column's two texels. Without UVs the texture is left out (white). */
#include "testutil.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const unsigned char texels[2][2][3] = { { { 255, 128, 0 }, { 64, 255, 32 } },
                                               { { 0, 16, 255 }, { 200, 100, 50 } } };

static double srgb_decode(unsigned char b)
{
    const double v = b / 255.0;
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

/* A glTF of one quad at y = 1 facing down (x, z in [-0.5, 0.5]) with UVs u0..u1 x 0..1, material emissive
 * (1, 0.5, 2) with the PNG as emissive texture; with_uv 0: no TEXCOORD_0. Buffer and image as data URIs. */
static void write_quad(const char *path, float u0, float u1, int with_uv)
{
    /* Two triangles, counter-clockwise seen from below; UVs: u along x, v along z. */
    const float pos[6][3] = { { -0.5f, 1, -0.5f }, { 0.5f, 1, -0.5f }, { -0.5f, 1, 0.5f },
                              { 0.5f, 1, -0.5f }, { 0.5f, 1, 0.5f }, { -0.5f, 1, 0.5f } };
    float uv[6][2];
    for (int i = 0; i < 6; i++) {
        uv[i][0] = pos[i][0] < 0 ? u0 : u1;
        uv[i][1] = pos[i][2] < 0 ? 0.0f : 1.0f;
    }
    unsigned char bin[sizeof pos + sizeof uv];
    memcpy(bin, pos, sizeof pos);
    memcpy(bin + sizeof pos, uv, sizeof uv);
    char b64[512], img[2048];
    tu_base64(bin, sizeof bin, b64);
    tu_png_base64(&texels[0][0][0], 2, 2, img, sizeof img);
    char js[8192];
    snprintf(js, sizeof js,
             "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
             "\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\",\"byteLength\":%zu}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},"
             "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\","
             "\"min\":[-0.5,1,-0.5],\"max\":[0.5,1,0.5]},{\"bufferView\":1,\"componentType\":5126,\"count\":6,"
             "\"type\":\"VEC2\"}],"
             "\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"emissiveFactor\":[1,0.5,2],\"emissiveTexture\":{\"index\":0}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0%s},\"material\":0}]}]}",
             b64, sizeof bin, sizeof pos, sizeof pos, sizeof uv, img, with_uv ? ",\"TEXCOORD_0\":1" : "");
    assert_int_equal(tu_write_file(path, js), 0);
}

static void load_light(const char *dir, float u0, float u1, int with_uv, ms_light *out)
{
    char gl[1024], sc_path[1024], text[2048];
    tu_path(gl, sizeof gl, dir, "quad.gltf");
    write_quad(gl, u0, u1, with_uv);
    snprintf(text, sizeof text,
             "{ \"meshes\": [ { \"file\": \"quad.gltf\" } ], \"camera\": { \"eye\": [0, 3, 3], \"target\": [0, 0, 0],"
             " \"up\": [0, 1, 0], \"fov_y\": 60, \"width\": 16, \"height\": 16 } }");
    assert_int_equal(tu_write_file(tu_path(sc_path, sizeof sc_path, dir, "quad.json"), text), 0);
    ms_scene sc;
    char err[512] = "";
    const ms_status st = ms_scene_load(sc_path, &sc, err, sizeof err);
    if (st) fprintf(stderr, "%s\n", err);
    assert_int_equal(st, MS_OK);
    size_t n;
    const ms_light *L = ms_scene_lights(&sc, &n);
    assert_int_equal((int)n, 1);
    assert_int_equal(L[0].shape, MS_LIGHT_RECT);   /* the two triangles merged into one parallelogram */
    *out = L[0];
    out->texture = NULL;
    ms_scene_free(&sc);
}

static void check(const ms_light *l, const double mean[3])
{
    const double factor[3] = { 1, 0.5, 2 };
    const float got[3] = { l->emission.x, l->emission.y, l->emission.z };
    for (int c = 0; c < 3; c++) {
        printf("channel %d: emission %.7g, factor x texel mean %.7g\n", c, got[c], factor[c] * mean[c]);
        assert_true(fabs(got[c] - factor[c] * mean[c]) <= 1e-5 * fmax(1.0, factor[c] * mean[c]));
    }
}

static void test_whole_texture(void **st)
{
    (void)st;
    ms_light l;
    load_light(tu_tmpdir("emissive_texture_whole"), 0.0f, 1.0f, 1, &l);
    double mean[3] = { 0, 0, 0 };
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 2; x++)
            for (int c = 0; c < 3; c++) mean[c] += srgb_decode(texels[y][x][c]) / 4.0;
    check(&l, mean);
}

static void test_left_column(void **st)
{
    (void)st;
    ms_light l;
    load_light(tu_tmpdir("emissive_texture_left"), 0.0f, 0.5f, 1, &l);
    double mean[3] = { 0, 0, 0 };
    for (int y = 0; y < 2; y++)
        for (int c = 0; c < 3; c++) mean[c] += srgb_decode(texels[y][0][c]) / 2.0;
    check(&l, mean);
}

static void test_no_uvs(void **st)
{
    (void)st;
    ms_light l;
    load_light(tu_tmpdir("emissive_texture_no_uv"), 0.0f, 1.0f, 0, &l);
    const double white[3] = { 1, 1, 1 };
    check(&l, white);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_whole_texture),
        cmocka_unit_test(test_left_column),
        cmocka_unit_test(test_no_uvs),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
