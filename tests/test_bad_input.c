/* Every bad input makes the CLI exit with 2 and one line "microshadow: ..." naming the file (where there
 * is one) and the problem, and leaves nothing in the output directory, not even a temporary file.
 * Each case changes one thing in a scene that renders fine (checked first). */
#include "testutil.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static char g_in[4096], g_out[4096];

/* The parts of a good scene; a case overrides one. */
typedef struct parts {
    const char *meshes, *eye, *target, *up, *fov, *size, *corner, *edge_s, *edge_t, *render;
} parts;

static const parts good = { "[ { \"file\": \"ok.obj\" } ]", "[0, 10, 12]", "[0, 0, 0]", "[0, 1, 0]", "60",
                            ", \"width\": 16, \"height\": 16", "[-1, 6, -1]", "[2, 0, 0]", "[0, 0, 2]",
                            "{ \"samples\": 256 }" };

static const char *write_scene(const char *name, const parts *p)
{
    static char path[4096];
    char text[4096];
    snprintf(text, sizeof text,
             "{ \"meshes\": %s,\n \"camera\": { \"eye\": %s, \"target\": %s, \"up\": %s, \"fov_y\": %s%s },\n"
             " \"light\": { \"corner\": %s, \"edge_s\": %s, \"edge_t\": %s },\n \"render\": %s }\n",
             p->meshes, p->eye, p->target, p->up, p->fov, p->size, p->corner, p->edge_s, p->edge_t, p->render);
    tu_path(path, sizeof path, g_in, name);
    assert_int_equal(tu_write_file(path, text), 0);
    return path;
}

static int setup(void **st)
{
    (void)st;
    snprintf(g_in, sizeof g_in, "%s", tu_tmpdir("bad_input_in"));
    snprintf(g_out, sizeof g_out, "%s", tu_tmpdir("bad_input_out"));
    char p[4096];
    tu_write_file(tu_path(p, sizeof p, g_in, "ok.obj"),
                  "v -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\nv -2 2 -2\nv 2 2 -2\nv 2 2 2\nv -2 2 2\n"
                  "f 1 3 2\nf 1 4 3\nf 5 7 6\nf 5 8 7\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "nan.obj"), "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "inf.obj"), "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "lines.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "points.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "junk.xyzzy"), "this is not a mesh in any format\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "junk.ply"), "ply\nformat nonsense 9.9\nelement vertex banana\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "malformed.json"), "{ \"meshes\": [ { \"file\": \"ok.obj\" } ],\n \"camera\": {\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "array.json"), "[1, 2, 3]\n");
    tu_write_file(tu_path(p, sizeof p, g_in, "empty.json"), "");
    mkdir(tu_path(p, sizeof p, g_in, "adir.json"), 0755);
    mkdir(tu_path(p, sizeof p, g_out, "existing_dir.png"), 0755);
    return 0;
}

/* Runs the CLI with the scene and extra flags, outputs into g_out, and checks exit 2, the message, and
 * that g_out holds exactly what it held before (only the pre-made directory). */
static void expect_bad(const char *scene, const char *const *extra, const char *const *needles)
{
    char png[4096], pfm[4096], json[4096], err[1024];
    tu_path(png, sizeof png, g_out, "out.png");
    tu_path(pfm, sizeof pfm, g_out, "out.pfm");
    tu_path(json, sizeof json, g_out, "stats.json");
    const char *args[48];
    int a = 0;
    if (scene) args[a++] = scene;
    args[a++] = "--quiet";
    int has_o = 0, has_vis = 0, has_stats = 0;
    for (int i = 0; extra && extra[i]; i++) {
        has_o |= !strcmp(extra[i], "-o");
        has_vis |= !strcmp(extra[i], "--vis");
        has_stats |= !strcmp(extra[i], "--stats");
    }
    if (!has_o) { args[a++] = "-o"; args[a++] = png; }
    if (!has_vis) { args[a++] = "--vis"; args[a++] = pfm; }
    if (!has_stats) { args[a++] = "--stats"; args[a++] = json; }
    for (int i = 0; extra && extra[i]; i++) args[a++] = extra[i];   /* last, so "--width" alone lacks its value */
    args[a] = NULL;
    int before = tu_count_entries(g_out);
    int rc = tu_run_cli(args, err, sizeof err);
    if (rc != 2) fail_msg("scene %s: exit %d, want 2 (stderr: %s)", scene ? scene : "(none)", rc, err);
    if (strncmp(err, "microshadow: ", 13) != 0) fail_msg("stderr line '%s' does not start with 'microshadow: '", err);
    for (int i = 0; needles[i]; i++)
        if (!strstr(err, needles[i])) fail_msg("stderr line '%s' does not contain '%s'", err, needles[i]);
    int after = tu_count_entries(g_out);
    if (after != before) fail_msg("'%s': the output directory holds %d entries afterwards, %d before", err, after, before);
}

#define NEEDLES(...) ((const char *const[]){ __VA_ARGS__, NULL })
#define FLAGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

static void test_good_scene_renders(void **st)
{
    (void)st;
    const char *dir = tu_tmpdir("bad_input_good");
    char png[4096], pfm[4096], json[4096], err[1024];
    const char *scene = write_scene("good.json", &good);
    const char *args[] = { scene, "--quiet", "-o", tu_path(png, sizeof png, dir, "a.png"), "--vis",
                           tu_path(pfm, sizeof pfm, dir, "a.pfm"), "--stats", tu_path(json, sizeof json, dir, "a.json"), NULL };
    int rc = tu_run_cli(args, err, sizeof err);
    if (rc != 0) fail_msg("the unmodified scene fails: exit %d: %s", rc, err);
    assert_int_equal(tu_count_entries(dir), 3);
}

static void test_files(void **st)
{
    (void)st;
    char p[4096];
    expect_bad(tu_path(p, sizeof p, g_in, "does_not_exist.json"), NULL, NEEDLES("does_not_exist.json", "cannot open"));
    expect_bad(tu_path(p, sizeof p, g_in, "adir.json"), NULL, NEEDLES("adir.json", "cannot read"));
    expect_bad(tu_path(p, sizeof p, g_in, "malformed.json"), NULL, NEEDLES("malformed.json", "malformed JSON near line 3"));
    expect_bad(tu_path(p, sizeof p, g_in, "empty.json"), NULL, NEEDLES("empty.json", "malformed JSON"));
    expect_bad(tu_path(p, sizeof p, g_in, "array.json"), NULL, NEEDLES("array.json", "top level must be an object"));
    expect_bad(tu_path(p, sizeof p, g_in, "junk.xyzzy"), NULL, NEEDLES("junk.xyzzy", "malformed JSON"));
    /* a mesh file given as the scene is read as that asset alone: its own faults are named */
    expect_bad(tu_path(p, sizeof p, g_in, "nan.obj"), NULL, NEEDLES("nan.obj", "NaN or infinite"));
    expect_bad(tu_path(p, sizeof p, g_in, "junk.ply"), NULL, NEEDLES("junk.ply", "unknown PLY format"));
    expect_bad(tu_path(p, sizeof p, g_in, "points.obj"), NULL, NEEDLES("points.obj", "no triangles"));
}

static void test_keys(void **st)
{
    (void)st;
    parts p;
    p = good; p.eye = "[0, 10]";
    expect_bad(write_scene("k1.json", &p), NULL, NEEDLES("k1.json", "camera.eye must be an array of 3 numbers"));
    p = good; p.fov = "\"60\"";
    expect_bad(write_scene("k2.json", &p), NULL, NEEDLES("k2.json", "camera.fov_y must be a finite number"));
    p = good; p.edge_t = "[0, \"0\", 2]";
    expect_bad(write_scene("k3.json", &p), NULL, NEEDLES("k3.json", "light.edge_t must be an array of 3 finite numbers"));
    p = good; p.meshes = "[ { \"name\": \"ok.obj\" } ]";
    expect_bad(write_scene("k4.json", &p), NULL, NEEDLES("k4.json", "meshes[0].file must be a non-empty string"));
    p = good; p.meshes = "[]";
    expect_bad(write_scene("k5.json", &p), NULL, NEEDLES("k5.json", "\"meshes\" must be a non-empty array"));
    p = good; p.render = "[256]";
    expect_bad(write_scene("k6.json", &p), NULL, NEEDLES("k6.json", "\"render\" must be an object"));
    /* Missing keys: write the JSON by hand. */
    char path[4096];
    tu_write_file(tu_path(path, sizeof path, g_in, "m1.json"),
                  "{ \"meshes\": [ { \"file\": \"ok.obj\" } ], \"camera\": { \"eye\": [0,10,12], \"target\": [0,0,0],"
                  " \"up\": [0,1,0], \"fov_y\": 60 } }");
    expect_bad(path, NULL, NEEDLES("m1.json", "\"light\" is missing"));
    tu_write_file(tu_path(path, sizeof path, g_in, "m2.json"),
                  "{ \"meshes\": [ { \"file\": \"ok.obj\" } ], \"camera\": { \"eye\": [0,10,12], \"target\": [0,0,0],"
                  " \"fov_y\": 60 }, \"light\": { \"corner\": [0,6,0], \"edge_s\": [1,0,0], \"edge_t\": [0,0,1] } }");
    expect_bad(path, NULL, NEEDLES("m2.json", "camera.up is missing"));
    tu_write_file(tu_path(path, sizeof path, g_in, "m3.json"),
                  "{ \"camera\": { \"eye\": [0,10,12], \"target\": [0,0,0], \"up\": [0,1,0], \"fov_y\": 60 },"
                  " \"light\": { \"corner\": [0,6,0], \"edge_s\": [1,0,0], \"edge_t\": [0,0,1] } }");
    expect_bad(path, NULL, NEEDLES("m3.json", "\"meshes\" is missing"));
    tu_write_file(tu_path(path, sizeof path, g_in, "m4.json"),
                  "{ \"meshes\": [ { \"file\": \"ok.obj\" } ], \"camera\": 5,"
                  " \"light\": { \"corner\": [0,6,0], \"edge_s\": [1,0,0], \"edge_t\": [0,0,1] } }");
    expect_bad(path, NULL, NEEDLES("m4.json", "\"camera\" must be an object"));
}

static void test_meshes(void **st)
{
    (void)st;
    parts p;
    p = good; p.meshes = "[ { \"file\": \"missing.obj\" } ]";
    expect_bad(write_scene("e1.json", &p), NULL, NEEDLES("missing.obj", "mesh file not found"));
    p = good; p.meshes = "[ { \"file\": \"junk.xyzzy\" } ]";
    expect_bad(write_scene("e2.json", &p), NULL, NEEDLES("junk.xyzzy", "unsupported mesh format"));
    p = good; p.meshes = "[ { \"file\": \"junk.ply\" } ]";
    expect_bad(write_scene("e3.json", &p), NULL, NEEDLES("junk.ply", "unknown PLY format"));
    p = good; p.meshes = "[ { \"file\": \"lines.obj\" } ]";
    expect_bad(write_scene("e4.json", &p), NULL, NEEDLES("lines.obj", "no triangles"));
    p = good; p.meshes = "[ { \"file\": \"points.obj\" } ]";
    expect_bad(write_scene("e5.json", &p), NULL, NEEDLES("points.obj"));
    p = good; p.meshes = "[ { \"file\": \"ok.obj\" }, { \"file\": \"nan.obj\" } ]";
    expect_bad(write_scene("e6.json", &p), NULL, NEEDLES("nan.obj", "NaN or infinite"));
    p = good; p.meshes = "[ { \"file\": \"inf.obj\" } ]";
    expect_bad(write_scene("e7.json", &p), NULL, NEEDLES("inf.obj", "NaN or infinite"));
    p = good; p.meshes = "[ { \"file\": \"adir.json\" } ]";
    expect_bad(write_scene("e8.json", &p), NULL, NEEDLES("adir.json", "not a regular file"));
}

static void test_values(void **st)
{
    (void)st;
    parts p;
    /* JSON has no NaN: the literal is malformed JSON; 1e999 parses to infinity. */
    p = good; p.eye = "[0, NaN, 12]";
    expect_bad(write_scene("v1.json", &p), NULL, NEEDLES("v1.json", "malformed JSON"));
    p = good; p.eye = "[0, 1e999, 12]";
    expect_bad(write_scene("v2.json", &p), NULL, NEEDLES("v2.json", "camera.eye", "finite"));
    p = good; p.corner = "[-1e999, 6, -1]";
    expect_bad(write_scene("v3.json", &p), NULL, NEEDLES("v3.json", "light.corner", "finite"));
    p = good; p.fov = "1e999";
    expect_bad(write_scene("v4.json", &p), NULL, NEEDLES("v4.json", "camera.fov_y must be a finite number"));
    p = good; p.edge_t = "[0, 0, 0]";
    expect_bad(write_scene("v5.json", &p), NULL, NEEDLES("v5.json", "light has zero area"));
    p = good; p.edge_t = "[4, 0, 0]";
    expect_bad(write_scene("v6.json", &p), NULL, NEEDLES("v6.json", "light has zero area"));
    p = good; p.target = "[0, 10, 12]";
    expect_bad(write_scene("v7.json", &p), NULL, NEEDLES("v7.json", "camera.eye equals camera.target"));
    p = good; p.up = "[0, 10, 12]";
    expect_bad(write_scene("v8.json", &p), NULL, NEEDLES("v8.json", "parallel to the view"));
    p = good; p.up = "[0, 0, 0]";
    expect_bad(write_scene("v9.json", &p), NULL, NEEDLES("v9.json", "camera.up"));
    p = good; p.fov = "180";
    expect_bad(write_scene("v10.json", &p), NULL, NEEDLES("v10.json", "fov_y must be in (0, 180)"));
    p = good; p.fov = "0";
    expect_bad(write_scene("v11.json", &p), NULL, NEEDLES("v11.json", "fov_y must be in (0, 180)"));
    p = good; p.size = ", \"width\": 0, \"height\": 16";
    expect_bad(write_scene("v12.json", &p), NULL, NEEDLES("v12.json", "camera.width must be an integer in [1, 16384]"));
    p = good; p.size = ", \"width\": 16, \"height\": 16385";
    expect_bad(write_scene("v13.json", &p), NULL, NEEDLES("v13.json", "camera.height must be an integer in [1, 16384]"));
    p = good; p.size = ", \"width\": 16.5, \"height\": 16";
    expect_bad(write_scene("v14.json", &p), NULL, NEEDLES("v14.json", "camera.width must be an integer"));
    /* camera.type (docs/cameras.md): the type by name, each type's own number required and in range */
    p = good; p.size = ", \"type\": \"spherical\"";
    expect_bad(write_scene("c1.json", &p), NULL, NEEDLES("c1.json", "camera.type must be \"pinhole\", \"orthographic\", "
                                                       "\"fisheye\", \"latlong\" or \"parabolic\""));
    p = good; p.size = ", \"type\": 2";
    expect_bad(write_scene("c2.json", &p), NULL, NEEDLES("c2.json", "camera.type must be \"pinhole\""));
    p = good; p.size = ", \"type\": \"orthographic\"";
    expect_bad(write_scene("c3.json", &p), NULL, NEEDLES("c3.json", "camera.ortho_height is missing"));
    p = good; p.size = ", \"type\": \"orthographic\", \"ortho_height\": 0";
    expect_bad(write_scene("c4.json", &p), NULL, NEEDLES("c4.json", "camera.ortho_height must be in (0, "));
    p = good; p.size = ", \"type\": \"orthographic\", \"ortho_height\": 1e300";
    expect_bad(write_scene("c5.json", &p), NULL, NEEDLES("c5.json", "camera.ortho_height = 1e+300 overflows a float"));
    p = good; p.size = ", \"type\": \"orthographic\", \"ortho_height\": 1e30";
    expect_bad(write_scene("c6.json", &p), NULL, NEEDLES("c6.json", "camera.ortho_height must be in (0, "));
    p = good; p.size = ", \"type\": \"fisheye\"";
    expect_bad(write_scene("c7.json", &p), NULL, NEEDLES("c7.json", "camera.fov is missing"));
    p = good; p.size = ", \"type\": \"fisheye\"";   /* good.fov is the pinhole's fov_y */
    expect_bad(write_scene("c7b.json", &p), NULL, NEEDLES("c7b.json", "camera.fov is missing (\"fov_y\" is another camera type's key)"));
    p = good; p.size = ", \"type\": \"fisheye\", \"fov\": 360.5";
    expect_bad(write_scene("c8.json", &p), NULL, NEEDLES("c8.json", "camera.fov must be in (0, 360] degrees"));
    p = good; p.size = ", \"type\": \"fisheye\", \"fov\": -10";
    expect_bad(write_scene("c9.json", &p), NULL, NEEDLES("c9.json", "camera.fov must be in (0, 360] degrees"));
    p = good; p.size = ", \"type\": \"fisheye\", \"fov\": \"wide\"";
    expect_bad(write_scene("c10.json", &p), NULL, NEEDLES("c10.json", "camera.fov must be a finite number"));
    p = good; p.size = ", \"type\": \"latlong\""; p.up = "[0, 0, 0]";
    expect_bad(write_scene("c11.json", &p), NULL, NEEDLES("c11.json", "camera.up"));
    /* the pinhole still needs fov_y in range when another type's key is given */
    p = good; p.fov = "200"; p.size = ", \"fov\": 100";
    expect_bad(write_scene("c12.json", &p), NULL, NEEDLES("c12.json", "fov_y must be in (0, 180)"));
    p = good; p.render = "{ \"samples\": 0 }";
    expect_bad(write_scene("v15.json", &p), NULL, NEEDLES("v15.json", "render.samples must be an integer"));
    p = good; p.render = "{ \"samples\": 100 }";
    expect_bad(write_scene("v16.json", &p), NULL, NEEDLES("v16.json", "samples must be 256, 1024 or 4096"));
    p = good; p.render = "{ \"samples\": \"many\" }";
    expect_bad(write_scene("v17.json", &p), NULL, NEEDLES("v17.json", "render.samples must be a finite number"));
}

static void test_flags(void **st)
{
    (void)st;
    const char *s = write_scene("flags.json", &good);
    expect_bad(s, FLAGS("--width", "0"), NEEDLES("--width", "not an integer in [1, 16384]"));
    expect_bad(s, FLAGS("--width", "16385"), NEEDLES("--width", "not an integer in [1, 16384]"));
    expect_bad(s, FLAGS("--height", "-3"), NEEDLES("--height", "not an integer"));
    expect_bad(s, FLAGS("--height", "12x"), NEEDLES("--height", "'12x'"));
    expect_bad(s, FLAGS("--samples", "100"), NEEDLES("--samples", "not one of 16, 64, 256, 1024, 4096"));
    expect_bad(s, FLAGS("--samples", "0"), NEEDLES("--samples"));
    expect_bad(s, FLAGS("--threads", "0"), NEEDLES("--threads"));
    expect_bad(s, FLAGS("--seed", "-1"), NEEDLES("--seed"));
    expect_bad(s, FLAGS("--method", "nosuch"), NEEDLES("--method", "'nosuch'", "not a known method"));
#ifndef MS_HAVE_EMBREE
    expect_bad(s, FLAGS("--method", "embree"), NEEDLES("--method", "not compiled into this build"));
#endif
    expect_bad(s, FLAGS("--pattern", "hex"), NEEDLES("--pattern", "'hex'"));
    expect_bad(s, FLAGS("--method", "scanline", "--pattern", "stratified"), NEEDLES("flags.json", "needs --pattern grid"));
    expect_bad(s, FLAGS("--method", "scanline", "--pattern", "interleaved"), NEEDLES("flags.json", "needs --pattern grid"));
    /* 16 and 64 samples only for the stratified pattern: the grid kernels' buffers are 16..64 wide, and an
     * interleaved pixel gets N/16 samples, which must fill a 16-ray packet */
    expect_bad(s, FLAGS("--method", "raytrace", "--samples", "16"), NEEDLES("flags.json", "256, 1024 or 4096 with the grid pattern", "got 16"));
    expect_bad(s, FLAGS("--method", "raytrace", "--pattern", "interleaved", "--samples", "64"),
               NEEDLES("flags.json", "256, 1024 or 4096 with the interleaved pattern", "got 64"));
    expect_bad(s, FLAGS("--method", "scanline", "--samples", "64"), NEEDLES("flags.json", "with the grid pattern"));
    expect_bad(s, FLAGS("--pattern", "Interleaved"), NEEDLES("--pattern", "'Interleaved'", "interleaved"));
    expect_bad(s, FLAGS("--frobnicate"), NEEDLES("--frobnicate", "unknown"));
    /* the strict parser (src/cli/options.c): a near miss is named, a far one is not explained as a typo */
    expect_bad(s, FLAGS("--metod", "scanline"), NEEDLES("unknown option '--metod'", "did you mean --method?"));
    expect_bad(s, FLAGS("--samles=256"), NEEDLES("'--samles=256'", "did you mean --samples?"));
    expect_bad(s, FLAGS("--frobnicate"), NEEDLES("see --help"));
    expect_bad(s, FLAGS("--method", "scanlin"), NEEDLES("'scanlin'", "not a known method", "did you mean scanline?"));
    /* a valued option given twice: neither is taken (the second would silently win) */
    char o1[4096], o2[4096];
    tu_path(o1, sizeof o1, g_out, "first.png");
    tu_path(o2, sizeof o2, g_out, "second.png");
    expect_bad(s, FLAGS("-o", o1, "-o", o2), NEEDLES("-o given twice", "first.png", "second.png"));
    expect_bad(s, FLAGS("--width", "8", "--width", "16"), NEEDLES("--width given twice ('8', then '16')"));
    /* an ending the CLI does not write is refused, not written as PNG bytes under that name */
    char jpg[4096], noext[4096], tiff[4096];
    expect_bad(s, FLAGS("-o", tu_path(jpg, sizeof jpg, g_out, "out.jpg")), NEEDLES("out.jpg", "-o needs a file ending in .png or .exr"));
    expect_bad(s, FLAGS("-o", tu_path(tiff, sizeof tiff, g_out, "out.tiff")), NEEDLES("out.tiff", ".png or .exr"));
    expect_bad(s, FLAGS("-o", tu_path(noext, sizeof noext, g_out, "out")), NEEDLES("-o needs a file ending in .png or .exr"));
    expect_bad(s, FLAGS("--stats", tu_path(noext, sizeof noext, g_out, "stats.txt")), NEEDLES("stats.txt", "--stats needs a file ending in .json"));
    expect_bad(s, FLAGS("--width"), NEEDLES("--width", "needs a value"));
    expect_bad(s, FLAGS(s), NEEDLES("more than one scene file"));
    char txt[4096];
    expect_bad(s, FLAGS("--vis", tu_path(txt, sizeof txt, g_out, "vis.txt")), NEEDLES("vis.txt", ".pfm or .exr"));
}

/* `microshadow bake` parses its options the same strict way. */
static void test_bake_flags(void **st)
{
    (void)st;
    const char *s = write_scene("bakeflags.json", &good);
    char err[1024], o1[4096], o2[4096];
    const char *typo[] = { "bake", s, "--quiet", "--sise", "64", NULL };
    assert_int_equal(tu_run_cli(typo, err, sizeof err), 2);
    if (!strstr(err, "microshadow bake: unknown option '--sise' (did you mean --size?)")) fail_msg("stderr: %s", err);
    const char *twice[] = { "bake", s, "--quiet", "-o", tu_path(o1, sizeof o1, g_out, "a.exr"), "-o",
                            tu_path(o2, sizeof o2, g_out, "b.exr"), NULL };
    assert_int_equal(tu_run_cli(twice, err, sizeof err), 2);
    if (!strstr(err, "-o given twice")) fail_msg("stderr: %s", err);
    const char *method[] = { "bake", s, "--quiet", "--method", "raytrac", NULL };
    assert_int_equal(tu_run_cli(method, err, sizeof err), 2);
    if (!strstr(err, "did you mean raytrace?")) fail_msg("stderr: %s", err);
    assert_int_equal(tu_count_entries(g_out), 1);   /* only the pre-made directory */
}

static void test_unwritable_outputs(void **st)
{
    (void)st;
    const char *s = write_scene("outs.json", &good);
    char p[4096];
    /* A directory that does not exist (root can write anywhere else, so permissions cannot be used). */
    expect_bad(s, FLAGS("-o", "/nonexistent-microshadow-dir/out.png"), NEEDLES("/nonexistent-microshadow-dir/out.png", "cannot write"));
    expect_bad(s, FLAGS("--vis", "/nonexistent-microshadow-dir/v.pfm"), NEEDLES("/nonexistent-microshadow-dir/v.pfm", "cannot write"));
    expect_bad(s, FLAGS("--vis", "/nonexistent-microshadow-dir/v.exr"), NEEDLES("v.exr", "cannot write"));
    expect_bad(s, FLAGS("--stats", "/nonexistent-microshadow-dir/s.json"), NEEDLES("s.json", "cannot write"));
    /* /proc refuses new files even to root. */
    expect_bad(s, FLAGS("-o", "/proc/microshadow.png"), NEEDLES("/proc/microshadow.png", "cannot write"));
    /* A path that is an existing directory: refused, and the other outputs are not written either. */
    expect_bad(s, FLAGS("-o", tu_path(p, sizeof p, g_out, "existing_dir.png")), NEEDLES("existing_dir.png", "is a directory"));
    expect_bad(s, FLAGS("--stats", tu_path(p, sizeof p, g_out, "existing_dir.png")), NEEDLES("existing_dir.png", "is a directory"));
    expect_bad(s, FLAGS("-o", ""), NEEDLES("empty output path"));
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_scene_renders),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_keys),
        cmocka_unit_test(test_meshes),
        cmocka_unit_test(test_values),
        cmocka_unit_test(test_flags),
        cmocka_unit_test(test_bake_flags),
        cmocka_unit_test(test_unwritable_outputs),
    };
    return tu_run_group_tests(tests, setup, NULL, argc, argv);
}
