/* Every output finite (issue 32 item 2):
 *   - light textures: an EXR texel above MS_MAX_LIGHT_TEXEL (the fuzzers' FLT_MAX texel among them) is one
 *     line naming the file and the texel; one at the limit loads;
 *   - lights: a radiance above MS_MAX_RADIANCE (given, or power over a tiny area) is one line;
 *   - the worst case the limits allow - 64 lights at MS_MAX_RADIANCE, textured at MS_MAX_LIGHT_TEXEL, large,
 *     close to the receivers - renders and bakes finite values (checked value by value here, not with the
 *     library's own check);
 *   - the last guard: a frame or lightmap holding a NaN or an infinity is refused by ms_outputs_write with
 *     one line naming the pixel, and no file appears;
 *   - every loadable input of the fuzz corpora (tests/fuzz/corpus: meshes, scenes, EXR and PNG light
 *     textures, MTL files) renders a frame whose every value is finite. */
#include "testutil.h"
#include <OpenEXR/openexr.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static char g_dir[4096];

static const char *in_dir(const char *name)
{
    static char p[4][4500];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", g_dir, name);
    return p[k];
}

/* Every value of the frame's planes, independently of ms_frame_check_finite; the first bad one into why. */
static int all_finite(const ms_frame *f, char *why, size_t n)
{
    const size_t np = (size_t)f->width * (size_t)f->height, nl = f->n_lights > 0 ? (size_t)f->n_lights : 1;
    const struct { const char *name; const float *p; size_t count; } planes[] = {
        { "rgb", f->rgb, 3 * np }, { "vis", f->vis, nl * np }, { "shadow", f->shadow, nl * np },
        { "shadow_spec", f->shadow_spec, nl * np } };
    for (size_t k = 0; k < sizeof planes / sizeof planes[0]; k++)
        for (size_t i = 0; planes[k].p && i < planes[k].count; i++)
            if (!isfinite(planes[k].p[i])) { snprintf(why, n, "%s[%zu] = %g", planes[k].name, i, (double)planes[k].p[i]); return 0; }
    if (f->rgb && !isfinite(f->exposure)) { snprintf(why, n, "exposure %g", (double)f->exposure); return 0; }
    return 1;
}

static const char *k_quad_obj = "v -10 0 -10\nv 10 0 10\nv 10 0 -10\nv -10 0 10\nv -2 2 -2\nv 2 2 2\n"
                                "v 2 2 -2\nv -2 2 2\nf 1 2 3\nf 1 4 2\nf 5 6 7\nf 5 8 6\n";

/* A scene file with the quad and `lights` (JSON text of the "lights" array's items). */
static const char *quad_scene(const char *name, const char *lights)
{
    assert_int_equal(tu_write_file(in_dir("q.obj"), k_quad_obj), 0);
    size_t n = strlen(lights) + 1024;
    char *text = malloc(n);
    assert_non_null(text);
    snprintf(text, n,
             "{\"meshes\": [{\"file\": \"q.obj\"}],\n"
             " \"camera\": {\"eye\": [0, 10, 12], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y\": 60, \"width\": 16, \"height\": 16},\n"
             " \"lights\": [%s], \"render\": {\"samples\": 256}}\n", lights);
    assert_int_equal(tu_write_file(in_dir(name), text), 0);
    free(text);
    return in_dir(name);
}

static void write_exr_const(const char *path, int w, int h, float value)
{
    float *pl = malloc((size_t)w * h * sizeof *pl);
    assert_non_null(pl);
    for (int i = 0; i < w * h; i++) pl[i] = value;
    const char *names[] = { "B", "G", "R" };
    const float *planes[] = { pl, pl, pl };
    assert_int_equal(tu_write_exr(path, w, h, 3, names, planes, 0, EXR_COMPRESSION_NONE), 0);
    free(pl);
}

static int one_line(const char *err, const char *name)
{
    return !strchr(err, '\n') && strstr(err, name) != NULL;
}

static void test_texel_limit(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("finite_texel"));
    ms_scene sc;
    char err[1024];
    write_exr_const(in_dir("over.exr"), 2, 2, 2e6f);
    write_exr_const(in_dir("at.exr"), 2, 2, MS_MAX_LIGHT_TEXEL);
    const char *l = "{\"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2], \"texture\": \"%s\"}";
    char lights[512];
    snprintf(lights, sizeof lights, l, "over.exr");
    assert_int_not_equal(ms_scene_load(quad_scene("over.json", lights), &sc, err, sizeof err), 0);
    printf("%s\n", err);
    assert_true(one_line(err, "over.exr") && strstr(err, "texel (0, 0)") && strstr(err, "2e+06"));
    snprintf(lights, sizeof lights, l, "at.exr");
    if (ms_scene_load(quad_scene("at.json", lights), &sc, err, sizeof err)) fail_msg("%s", err);
    ms_scene_free(&sc);
    /* the fuzzers' finding: texels of FLT_MAX, which made 28 pixels NaN */
    char src[4096];
    snprintf(src, sizeof src, "%s/crashes/exr/exr-flt-max-texel.exr", MS_FUZZ_DIR);
    FILE *a = fopen(src, "rb"), *b = fopen(in_dir("flt_max.exr"), "wb");
    assert_true(a && b);
    char buf[4096];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, a)) > 0) assert_int_equal(fwrite(buf, 1, k, b), k);
    fclose(a);
    fclose(b);
    snprintf(lights, sizeof lights, l, "flt_max.exr");
    const char *scene = quad_scene("flt_max.json", lights);
    char out[4400];
    snprintf(out, sizeof out, "%s/flt_max.exr.out.exr", g_dir);
    const char *args[] = { scene, "--quiet", "-o", out, NULL };
    char all[2048];
    tu_run_result res;
    tu_run_opts ro = { 0, -1, 0 };
    assert_int_equal(tu_run_cli_ex(args, &ro, all, sizeof all, &res), 2);
    printf("%s", all);
    assert_int_equal(res.lines, 1);
    assert_non_null(strstr(all, "flt_max.exr: texel ("));
    assert_false(tu_file_exists(out));
    /* the API: a texel beyond the limit in a scene built in code */
    tu_make_quad(&sc);
    float tex[3] = { 1, 1e7f, 1 };
    sc.light.texture = tex;
    sc.light.texture_width = sc.light.texture_height = 1;
    assert_int_not_equal(ms_scene_validate(&sc, "code", err, sizeof err), 0);
    assert_non_null(strstr(err, "texel (0, 0) is 1e+07"));
    sc.light.texture = NULL;
    ms_scene_free(&sc);
}

static void test_radiance_limit(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("finite_radiance"));
    ms_scene sc;
    char err[1024];
    assert_int_not_equal(ms_scene_load(quad_scene("e.json", "{\"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], "
                                                  "\"edge_t\": [0, 0, 2], \"emission\": [1, 3e20, 1]}"), &sc, err, sizeof err), 0);
    printf("%s\n", err);
    assert_true(one_line(err, "e.json") && strstr(err, "lights[0]") && strstr(err, "3e+20"));
    /* 1e15 W from 1e-12 square units: radiance 1e15 / (pi 1e-12) = 3.2e26 */
    assert_int_not_equal(ms_scene_load(quad_scene("p.json", "{\"corner\": [-1, 6, -1], \"edge_s\": [1e-6, 0, 0], "
                                                  "\"edge_t\": [0, 0, 1e-6], \"power\": 1e15}"), &sc, err, sizeof err), 0);
    printf("%s\n", err);
    assert_true(one_line(err, "p.json") && strstr(err, "radiance"));
    if (ms_scene_load(quad_scene("ok.json", "{\"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], \"edge_t\": [0, 0, 2], "
                                 "\"emission\": 1e20}"), &sc, err, sizeof err))
        fail_msg("%s", err);
    ms_scene_free(&sc);
}

/* 64 lights at the limits, 1000 x 1000 units each, 0.5 above the occluder: every value finite. */
static void test_worst_case_finite(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("finite_worst"));
    write_exr_const(in_dir("max.exr"), 2, 2, MS_MAX_LIGHT_TEXEL);
    char *lights = malloc(64 * 256);
    assert_non_null(lights);
    lights[0] = 0;
    for (int i = 0; i < 64; i++) {
        char one[256];
        snprintf(one, sizeof one, "%s{\"corner\": [-500, %g, -500], \"edge_s\": [1000, 0, 0], \"edge_t\": [0, 0, 1000], "
                 "\"emission\": 1e20, \"texture\": \"max.exr\"}", i ? ", " : "", 2.5 + 0.001 * i);
        strcat(lights, one);
    }
    ms_scene sc;
    char err[1024], why[256];
    if (ms_scene_load(quad_scene("worst.json", lights), &sc, err, sizeof err)) fail_msg("%s", err);
    free(lights);
    sc.camera.width = sc.camera.height = 12;
    ms_render_options o;
    tu_render_options_default(&o);
    o.samples = 256;
    o.threads = 2;
    const char *methods[] = { "scanline", "raytrace" };
    for (int m = 0; m < 2; m++) {
        o.method = methods[m];
        ms_frame f;
        if (ms_render(&sc, &o, &f, err, sizeof err)) fail_msg("%s", err);
        if (!all_finite(&f, why, sizeof why)) fail_msg("%s: %s", methods[m], why);
        float mx = 0;
        for (int i = 0; i < 3 * f.width * f.height; i++) mx = fmaxf(mx, f.rgb[i]);
        printf("64 lights at radiance %g x texel %g, %s: largest pixel value %g (FLT_MAX %g)\n", (double)MS_MAX_RADIANCE,
               (double)MS_MAX_LIGHT_TEXEL, methods[m], (double)mx, 3.4e38);
        assert_true(mx > 1e25f);   /* the lights did reach the image */
        ms_frame_free(&f);
    }
    ms_bake_options bo;
    memset(&bo, 0, sizeof bo);
    bo.size = 16;
    bo.uv_set = -1;
    bo.points.samples = 256;
    bo.points.threads = 2;
    ms_lightmap lm;
    ms_status s = ms_bake(&sc, NULL, &bo, &lm, err, sizeof err);
    if (s) fail_msg("bake: %s", err);
    if (!all_finite(&lm.frame, why, sizeof why)) fail_msg("bake: %s", why);
    ms_lightmap_free(&lm);
    ms_scene_free(&sc);
}

/* The last guard: a NaN, or an infinity, anywhere in a frame: one line naming the pixel, no file. */
static void test_guard_before_writing(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("finite_guard"));
    enum { W = 5, H = 4 };
    float vis[2 * W * H], sh[2 * W * H], rgb[3 * W * H];
    for (int i = 0; i < 2 * W * H; i++) vis[i] = sh[i] = 0.5f;
    for (int i = 0; i < 3 * W * H; i++) rgb[i] = 1.0f;
    ms_frame f;
    memset(&f, 0, sizeof f);
    f.width = W;
    f.height = H;
    f.vis = vis;
    f.shadow = sh;
    f.rgb = rgb;
    f.exposure = 1.0f;
    f.n_lights = 2;
    char err[1024];
    assert_int_equal(ms_write_png(&f, in_dir("ok.png"), err, sizeof err), 0);
    struct { float *p; int at; float v; const char *want; } cases[] = {
        { rgb, 3 * (2 * W + 3) + 1, NAN, "G at pixel (3, 2) is NaN" },
        { sh, W * H + 1 * W + 4, INFINITY, "S of light 1 at pixel (4, 1) is infinite" },
        { vis, 0, -INFINITY, "V of light 0 at pixel (0, 0) is infinite" },
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const float keep = cases[c].p[cases[c].at];
        cases[c].p[cases[c].at] = cases[c].v;
        const char *target = in_dir("bad.exr");
        ms_output outs[2] = { { "-o", target, ms_exr_write_stream, NULL, NULL, 0 },
                                { "--vis", in_dir("bad.pfm"), ms_vis_write_stream, NULL, NULL, 0 } };
        assert_int_equal(ms_outputs_check(outs, 2, err, sizeof err), 0);
        assert_int_not_equal(ms_outputs_write(&f, outs, 2, err, sizeof err), 0);
        printf("%s\n", err);
        assert_true(one_line(err, cases[c].want) && !strncmp(err, target, strlen(target)));
        assert_false(tu_file_exists(target));
        assert_false(tu_file_exists(in_dir("bad.pfm")));
        cases[c].p[cases[c].at] = keep;
    }
    assert_int_equal(tu_count_entries(g_dir), 1);   /* ok.png only: no staging file left */
}

/* ---- every loadable input of the fuzz corpora ---- */

static int copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    if (!a || !b) { if (a) fclose(a); if (b) fclose(b); return -1; }
    char buf[65536];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, a)) > 0) fwrite(buf, 1, k, b);
    fclose(a);
    return fclose(b);
}

static void warn_quietly(void *user, const char *msg) { (void)user; (void)msg; }

/* Renders sc at 12x12 with a camera and a light fitted to its bounding box (keep_view: the scene's own
 * camera and lights); every value must be finite. */
static void render_finite(ms_scene *sc, int keep_view, const char *what, int *rendered)
{
    if (!keep_view) {
        float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
        for (size_t i = 0; i < 3 * sc->n_tris; i++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], sc->tri[3 * i + k]);
                hi[k] = fmaxf(hi[k], sc->tri[3 * i + k]);
            }
        float c[3], r = 0;
        for (int k = 0; k < 3; k++) { c[k] = 0.5f * lo[k] + 0.5f * hi[k]; r = fmaxf(r, 0.5f * hi[k] - 0.5f * lo[k]); }
        r = fmaxf(r, 1e-3f * fmaxf(fabsf(c[0]), fmaxf(fabsf(c[1]), fabsf(c[2])))) + 1e-3f;
        sc->camera.type = MS_CAMERA_PINHOLE;
        sc->camera.eye = (ms_vec3){ c[0] + 2 * r, c[1] + 3 * r, c[2] + 2.5f * r };
        sc->camera.target = (ms_vec3){ c[0], c[1], c[2] };
        sc->camera.up = (ms_vec3){ 0, 1, 0 };
        sc->camera.fov_y = 60;
        ms_light *l = sc->n_lights ? &sc->lights[0] : &sc->light;
        const float *tex = l->texture;
        const int tw = l->texture_width, th = l->texture_height;
        memset(l, 0, sizeof *l);
        l->corner = (ms_vec3){ c[0] - r, c[1] + 4 * r, c[2] - r };
        l->edge_s = (ms_vec3){ 2 * r, 0, 0 };
        l->edge_t = (ms_vec3){ 0, 0, 2 * r };
        l->emission = (ms_vec3){ 1, 1, 1 };
        l->texture = tex;
        l->texture_width = tw;
        l->texture_height = th;
        if (sc->n_lights) sc->light = sc->lights[0];
    }
    sc->camera.width = sc->camera.height = 12;
    char err[1024], why[256];
    if (ms_scene_validate(sc, what, err, sizeof err)) return;   /* e.g. coordinates too large to frame */
    ms_render_options o;
    tu_render_options_default(&o);
    o.samples = 256;
    o.threads = 2;
    ms_frame f;
    if (getenv("TF_DEBUG")) fprintf(stderr, "render %s\n", what);   /* which input, when a sanitizer ends the test */
    if (ms_render(sc, &o, &f, err, sizeof err)) fail_msg("%s: render failed: %s", what, err);
    if (!all_finite(&f, why, sizeof why)) fail_msg("%s: %s", what, why);
    ms_frame_free(&f);
    (*rendered)++;
}

static void test_fuzz_corpora_render_finite(void **st)
{
    (void)st;
    snprintf(g_dir, sizeof g_dir, "%s", tu_tmpdir("finite_corpora"));
    ms_set_warning_handler(warn_quietly, NULL);
    assert_int_equal(tu_write_file(in_dir("q.obj"), k_quad_obj), 0);
    assert_int_equal(tu_write_file(in_dir("a.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n"), 0);
    DIR *td = opendir(MS_FUZZ_DIR "/corpus");
    assert_non_null(td);
    struct dirent *te;
    int total = 0, loaded = 0, rendered = 0;
    while ((te = readdir(td))) {
        if (te->d_name[0] == '.') continue;
        const char *t = te->d_name;
        char dir[4400];
        snprintf(dir, sizeof dir, "%s/corpus/%s", MS_FUZZ_DIR, t);
        DIR *d = opendir(dir);
        if (!d) continue;
        struct dirent *e;
        while ((e = readdir(d))) {
            if (e->d_name[0] == '.') continue;
            char src[4700], name[300], scene[8192];
            snprintf(src, sizeof src, "%s/%s", dir, e->d_name);
            total++;
            int keep_view = 0;
            /* the input as the file a scene names */
            if (!strcmp(t, "scene")) {
                assert_int_equal(copy_file(src, in_dir("scene.json")), 0);
                keep_view = 1;
            } else {
                const int tex = !strcmp(t, "exr") || !strcmp(t, "png"), mtl = !strcmp(t, "mtl");
                snprintf(name, sizeof name, "input.%s", tex || mtl ? t : !strcmp(t, "gltf") ? "glb" : t);
                /* .glb and .gltf are told apart by content (cgltf), so either name reads both */
                assert_int_equal(copy_file(src, in_dir(name)), 0);
                if (mtl)
                    assert_int_equal(tu_write_file(in_dir("m.obj"), "mtllib input.mtl\nv -1 0 -1\nv 1 0 1\nv 1 0 -1\nv 0 1 0\n"
                                                   "vt 0 0\nvt 1 1\nvt 1 0\nusemtl a\nf 1/1 2/2 3/3\nusemtl red\nf 1/1 4/2 2/3\n"), 0);
                snprintf(scene, sizeof scene,
                         "{\"meshes\": [{\"file\": \"%s\"}], \"camera\": {\"eye\": [0, 10, 12], \"target\": [0, 0, 0], "
                         "\"up\": [0, 1, 0], \"fov_y\": 60}, \"light\": {\"corner\": [-1, 6, -1], \"edge_s\": [2, 0, 0], "
                         "\"edge_t\": [0, 0, 2]%s%s%s}}\n",
                         tex ? "q.obj" : mtl ? "m.obj" : name, tex ? ", \"texture\": \"" : "", tex ? name : "", tex ? "\"" : "");
                assert_int_equal(tu_write_file(in_dir("scene.json"), scene), 0);
            }
            ms_scene sc;
            char err[1024];
            if (ms_scene_load(in_dir("scene.json"), &sc, err, sizeof err)) continue;   /* not loadable */
            loaded++;
            if (sc.n_tris && !sc.procedural.type) render_finite(&sc, keep_view || !strcmp(t, "exr") || !strcmp(t, "png"), src, &rendered);
            ms_scene_free(&sc);
        }
        closedir(d);
    }
    closedir(td);
    ms_set_warning_handler(NULL, NULL);
    printf("fuzz corpora: %d inputs, %d loadable, %d rendered with every value finite\n", total, loaded, rendered);
    assert_true(rendered >= 30);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_texel_limit),
        cmocka_unit_test(test_radiance_limit),
        cmocka_unit_test(test_worst_case_finite),
        cmocka_unit_test(test_guard_before_writing),
        cmocka_unit_test(test_fuzz_corpora_render_finite),
    };
    return tu_run_group_tests(tests, NULL, NULL, argc, argv);
}
