/* A downloaded asset reads only its own files (issue 30 item 6, issue 32 item 3): the files a mesh names -
 * glTF buffer and image URIs, an OBJ's mtllib, an MTL's map_Kd and map_d - must resolve inside the folder of
 * the file naming them. Absolute paths, `..` leading out (also percent-encoded in a URI) and symbolic links
 * resolving outside are one error line naming the file and the path (CLI: exit 2), unless the scene says
 * "allow_outside_paths": true or the caller sets ms_scene_load_options.allow_outside_paths. Oracles: the
 * triangle's coordinates written into the outside buffer, the outside MTL's colour, the outside PNG's size
 * appear exactly when the file was allowed; paths that stay inside (sub/.., a link within) always load. */
#include "testutil.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char g_root[4096], g_asset[4200], g_out[4200];

static const char *at(const char *dir, const char *name)
{
    static char p[8][4096];
    static int k;
    k = (k + 1) % 8;
    return tu_path(p[k], sizeof p[k], dir, name);
}

static const float k_tri[9] = { 0, 0, 0, 2, 0, 0, 0, 3, 0 };

static void write_bytes(const char *path, const void *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

static void write_png(const char *path, int w, int h)
{
    ms_frame f;
    memset(&f, 0, sizeof f);
    f.width = w;
    f.height = h;
    float vis[16] = { 0 }, rgb[48];
    for (int i = 0; i < 48; i++) rgb[i] = 0.5f;
    f.vis = vis;
    f.rgb = rgb;
    f.exposure = 1.0f;
    char err[256];
    assert_int_equal(ms_write_png(&f, path, err, sizeof err), 0);
}

static int setup(void **st)
{
    (void)st;
    snprintf(g_root, sizeof g_root, "%s", tu_tmpdir("asset_paths"));
    snprintf(g_asset, sizeof g_asset, "%s/asset", g_root);
    snprintf(g_out, sizeof g_out, "%s/outside", g_root);
    mkdir(g_asset, 0755);
    mkdir(g_out, 0755);
    mkdir(at(g_asset, "sub"), 0755);
    /* outside the asset's folder: a buffer, an image, an MTL (red) and its map */
    write_bytes(at(g_out, "tri.bin"), k_tri, sizeof k_tri);
    write_png(at(g_out, "tex.png"), 3, 2);
    assert_int_equal(tu_write_file(at(g_out, "x.mtl"), "newmtl m\nKd 1 0 0\n"), 0);
    /* inside: the same buffer and image, and links pointing out and in */
    write_bytes(at(g_asset, "in.bin"), k_tri, sizeof k_tri);
    write_png(at(g_asset, "in.png"), 3, 2);
    assert_int_equal(symlink("../outside/tri.bin", at(g_asset, "out_link.bin")), 0);
    assert_int_equal(symlink("../outside/tex.png", at(g_asset, "out_link.png")), 0);
    assert_int_equal(symlink("../outside/x.mtl", at(g_asset, "out_link.mtl")), 0);
    assert_int_equal(symlink(g_out, at(g_asset, "out_dir")), 0);   /* a folder link: out_dir/tri.bin */
    assert_int_equal(symlink("in.bin", at(g_asset, "in_link.bin")), 0);
    return 0;
}

/* Loads asset/<mesh> through a scene file beside it; 0 or -1 with err. allow_key: the scene file's switch;
 * api: ms_scene_load_options. */
static int load(const char *mesh, const char *mesh_text, int allow_key, int api, ms_scene *sc, char *err, size_t n)
{
    assert_int_equal(tu_write_file(at(g_asset, mesh), mesh_text), 0);
    char text[1024];
    snprintf(text, sizeof text,
             "{%s\"meshes\": [{\"file\": \"%s\"}],\n"
             " \"camera\": {\"eye\": [0.5, 1, 5], \"target\": [0.5, 1, 0], \"up\": [0, 1, 0], \"fov_y\": 60, \"width\": 16, \"height\": 16},\n"
             " \"light\": {\"corner\": [-1, -1, 3], \"edge_s\": [4, 0, 0], \"edge_t\": [0, 4, 0]}}\n",
             allow_key ? "\"allow_outside_paths\": true, " : "", mesh);
    assert_int_equal(tu_write_file(at(g_asset, "scene.json"), text), 0);
    ms_scene_load_options o = { api };
    err[0] = 0;
    return ms_scene_load_ex(at(g_asset, "scene.json"), &o, sc, err, n);
}

/* The refusal: one line, naming the file that names the path and the path as written. */
static void assert_refused(int rc, const char *err, const char *owner, const char *ref)
{
    if (rc == 0) fail_msg("'%s' named by %s was read; expected a refusal", ref, owner);
    assert_null(strchr(err, '\n'));
    const char *p = at(g_asset, owner);
    if (strncmp(err, p, strlen(p)) || !strstr(err, ref)) fail_msg("message '%s' must name %s and '%s'", err, p, ref);
}

static char *gltf(const char *buffer_uri, const char *image_uri)
{
    static char t[2048];
    snprintf(t, sizeof t,
             "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"%s\", \"byteLength\": 36}],\n"
             " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],\n"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [2, 3, 0]}],\n"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}],\n"
             " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}],\n"
             " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"%s\"}],\n"
             " \"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}], \"scene\": 0}\n",
             buffer_uri, image_uri);
    return t;
}

static void check_gltf_loaded(const ms_scene *sc)
{
    assert_int_equal(sc->n_tris, 1);
    for (int i = 0; i < 9; i++) assert_true(sc->tri[i] == k_tri[i]);
    assert_int_equal(sc->n_textures, 1);
    assert_int_equal(sc->textures[0].width, 3);
    assert_int_equal(sc->textures[0].height, 2);
}

static void test_gltf_buffer_uris(void **st)
{
    (void)st;
    char abs_bin[4300];
    snprintf(abs_bin, sizeof abs_bin, "%s/tri.bin", g_out);
    const char *outward[] = { "../outside/tri.bin", "%2E%2E/outside/tri.bin", "sub/../../outside/tri.bin", abs_bin,
                              "out_link.bin", "out_dir/tri.bin" };
    char err[1024];
    ms_scene sc;
    for (size_t i = 0; i < sizeof outward / sizeof outward[0]; i++) {
        assert_refused(load("b.gltf", gltf(outward[i], "in.png"), 0, 0, &sc, err, sizeof err), err, "b.gltf", outward[i]);
        assert_non_null(strstr(err, "buffer 0 uri"));
        for (int api = 0; api < 2; api++) {   /* allowed by the scene file, or by the API option */
            if (load("b.gltf", gltf(outward[i], "in.png"), !api, api, &sc, err, sizeof err)) fail_msg("%s", err);
            check_gltf_loaded(&sc);
            ms_scene_free(&sc);
        }
    }
    /* inside, also through `..` that stays in and a link that stays in */
    const char *inward[] = { "in.bin", "sub/../in.bin", "./in.bin", "in_link.bin", "%69n.bin" };
    for (size_t i = 0; i < sizeof inward / sizeof inward[0]; i++) {
        if (load("b.gltf", gltf(inward[i], "in.png"), 0, 0, &sc, err, sizeof err)) fail_msg("%s: %s", inward[i], err);
        check_gltf_loaded(&sc);
        ms_scene_free(&sc);
    }
}

static void test_gltf_image_uris(void **st)
{
    (void)st;
    char abs_png[4300];
    snprintf(abs_png, sizeof abs_png, "%s/tex.png", g_out);
    const char *outward[] = { "../outside/tex.png", "%2e%2e/outside/tex.png", abs_png, "out_link.png" };
    char err[1024];
    ms_scene sc;
    for (size_t i = 0; i < sizeof outward / sizeof outward[0]; i++) {
        assert_refused(load("i.gltf", gltf("in.bin", outward[i]), 0, 0, &sc, err, sizeof err), err, "i.gltf", outward[i]);
        assert_non_null(strstr(err, "image 0 uri"));
        if (load("i.gltf", gltf("in.bin", outward[i]), 1, 0, &sc, err, sizeof err)) fail_msg("%s", err);
        check_gltf_loaded(&sc);
        ms_scene_free(&sc);
    }
}

static void test_mtllib(void **st)
{
    (void)st;
    char abs_mtl[4300];
    snprintf(abs_mtl, sizeof abs_mtl, "%s/x.mtl", g_out);
    const char *outward[] = { "../outside/x.mtl", abs_mtl, "out_link.mtl", "out_dir/x.mtl" };
    char err[1024], obj[4600];
    ms_scene sc;
    for (size_t i = 0; i < sizeof outward / sizeof outward[0]; i++) {
        snprintf(obj, sizeof obj, "mtllib %s\nv 0 0 0\nv 2 0 0\nv 0 3 0\nusemtl m\nf 1 2 3\n", outward[i]);
        assert_refused(load("m.obj", obj, 0, 0, &sc, err, sizeof err), err, "m.obj", outward[i]);
        assert_non_null(strstr(err, "mtllib"));
        if (load("m.obj", obj, 1, 0, &sc, err, sizeof err)) fail_msg("%s", err);
        assert_int_equal(sc.n_tris, 1);   /* the outside MTL was read: its red */
        assert_int_equal(sc.n_materials, 1);
        assert_true(sc.materials[0].base_color[0] == 1.0f && sc.materials[0].base_color[1] == 0.0f);
        ms_scene_free(&sc);
    }
    /* the fuzzers' obj-mtllib-absolute-leak form: assimp takes \f for a line end and skips blanks after it */
    const char *hidden = "v 0 0 0\nv 2 0 0\nv 0 3 0\nf 1 2 3\n\f\f  mtllib\t/1\n";
    assert_refused(load("h.obj", hidden, 0, 0, &sc, err, sizeof err), err, "h.obj", "/1");
    /* inside: read, its colour used */
    assert_int_equal(tu_write_file(at(g_asset, "sub/in.mtl"), "newmtl m\nKd 0 1 0\n"), 0);
    if (load("m.obj", "mtllib sub/../sub/in.mtl\nv 0 0 0\nv 2 0 0\nv 0 3 0\nusemtl m\nf 1 2 3\n", 0, 0, &sc, err, sizeof err))
        fail_msg("%s", err);
    assert_int_equal(sc.n_materials, 1);
    assert_true(sc.materials[0].base_color[1] == 1.0f);
    ms_scene_free(&sc);
}

static void test_mtl_maps(void **st)
{
    (void)st;
    char abs_png[4300];
    snprintf(abs_png, sizeof abs_png, "%s/tex.png", g_out);
    const char *outward[] = { "../outside/tex.png", abs_png, "out_link.png" };
    const char *keys[] = { "map_Kd", "map_d" };
    char err[1024], mtl[4600];
    ms_scene sc;
    const char *obj = "mtllib t.mtl\nv 0 0 0\nv 2 0 0\nv 0 3 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
    for (size_t k = 0; k < 2; k++)
        for (size_t i = 0; i < sizeof outward / sizeof outward[0]; i++) {
            snprintf(mtl, sizeof mtl, "newmtl m\n%s -bm 1 %s\n", keys[k], outward[i]);
            assert_int_equal(tu_write_file(at(g_asset, "t.mtl"), mtl), 0);
            /* the refusal names the MTL file, the key and the path */
            assert_refused(load("t.obj", obj, 0, 0, &sc, err, sizeof err), err, "t.mtl", outward[i]);
            assert_non_null(strstr(err, keys[k]));
            if (load("t.obj", obj, 0, 1, &sc, err, sizeof err)) fail_msg("%s", err);
            assert_int_equal(sc.n_textures, 1);
            assert_int_equal(sc.textures[0].width, 3);
            ms_scene_free(&sc);
        }
    assert_int_equal(tu_write_file(at(g_asset, "t.mtl"), "newmtl m\nmap_Kd sub/../in.png\n"), 0);
    if (load("t.obj", obj, 0, 0, &sc, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(sc.n_textures, 1);
    ms_scene_free(&sc);
}

/* The CLI: one line on stderr, exit 2, no output file. */
static void test_cli_exit_2(void **st)
{
    (void)st;
    char err[1024];
    ms_scene sc;
    assert_int_not_equal(load("c.gltf", gltf("../outside/tri.bin", "in.png"), 0, 0, &sc, err, sizeof err), 0);
    char out[4200], line[1024];
    snprintf(out, sizeof out, "%s/c.png", g_root);
    const char *args[] = { at(g_asset, "scene.json"), "-o", out, "--quiet", NULL };
    char all[4096];
    tu_run_result res;
    tu_run_opts ro = { 0, -1, 0 };
    assert_int_equal(tu_run_cli_ex(args, &ro, all, sizeof all, &res), 2);
    assert_int_equal(res.lines, 1);
    snprintf(line, sizeof line, "microshadow: %s", at(g_asset, "c.gltf"));
    assert_int_equal(strncmp(all, line, strlen(line)), 0);
    assert_false(tu_file_exists(out));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gltf_buffer_uris),
        cmocka_unit_test(test_gltf_image_uris),
        cmocka_unit_test(test_mtllib),
        cmocka_unit_test(test_mtl_maps),
        cmocka_unit_test(test_cli_exit_2),
    };
    return tu_run_group_tests(tests, setup, NULL, argc, argv);
}
