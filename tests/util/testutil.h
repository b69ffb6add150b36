/* Shared helpers for the cmocka tests. */
#ifndef MS_TESTUTIL_H
#define MS_TESTUTIL_H
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include "microshadow.h"

/* Runs the cmocka tests[0..n) of a program, all of them or the part its command line selects (to run or time one
 * test alone, or to make one long program several ctest entries that `ctest -j` runs side by side):
 *   PROGRAM                          every test;
 *   PROGRAM --only NAME[,NAME...]    the tests named;
 *   PROGRAM --except NAME[,NAME...]  every test but those named (a program's last part, where a test added
 *                                    later runs without anyone listing it).
 * A name that is no test of the program, or any other argument, fails the run (exit 1), so that a renamed
 * test cannot drop out of its part unnoticed. Returns what cmocka's run returns. */
int tu_run_tests(const char *group, const struct CMUnitTest *tests, size_t n, CMFixtureFunction setup,
                 CMFixtureFunction teardown, int argc, char **argv);
#define tu_run_group_tests(tests, setup, teardown, argc, argv) \
    tu_run_tests(#tests, tests, sizeof(tests) / sizeof((tests)[0]), setup, teardown, argc, argv)

/* A fresh directory under the build tree for this test program; returns its path. */
const char *tu_tmpdir(const char *test_name);
/* Path buf = dir/name. */
const char *tu_path(char *buf, size_t n, const char *dir, const char *name);
int tu_write_file(const char *path, const char *text);
/* Writes a w x h PNG whose linear texels are rgb (ms_write_png, exposure 1): values 0 or 1 survive the 8-bit
 * sRGB round trip exactly, for light and material textures. Fails the test when it cannot. */
void tu_write_texture_png(const char *path, int w, int h, const float *rgb);
/* Base64 of in[0..n) into out (4 ceil(n/3) characters and a NUL), for glTF data: URIs written by tests. */
void tu_base64(const unsigned char *in, size_t n, char *out);
/* An 8-bit RGB image of w x h texels (rows top first) as a PNG (libpng), base64-encoded into out[cap]: the payload
 * of a glTF "data:image/png;base64," URI. Fails the test when it does not fit. */
void tu_png_base64(const unsigned char *rgb, int w, int h, char *out, size_t cap);
/* Reads channel `name` of a one-part scanline EXR of w x h pixels as floats into img (rows top to
 * bottom); -1 when it has no such channel. */
int tu_read_exr_channel(const char *path, const char *name, int w, int h, float *img);
/* Writes a one-part scanline EXR of w x h with nch channels (names[c], plane[c]: w*h floats, row 0 first),
 * each stored as half (half != 0; the values must be exact halves) or float, with the given compression
 * (an exr_compression_t). 0, or -1. */
int tu_write_exr(const char *path, int w, int h, int nch, const char *const *names, const float *const *plane, int half,
                 int compression);
int tu_file_exists(const char *path);
/* Number of entries in dir other than . and .. (to prove nothing was left behind). */
int tu_count_entries(const char *dir);
/* Runs the CLI with argv (NULL-terminated, without argv[0]); returns its exit status and the first
 * line of its stderr in err_line. */
int tu_run_cli(const char *const *args, char *err_line, size_t n);
/* tu_run_cli with limits: the child's file size limit (0: none; SIGXFSZ is ignored so writes fail with
 * EFBIG, as on a full disk), umask (-1: inherited) and a time limit (seconds, 0: 120). Returns the exit
 * status (128 + signal if killed), all of stderr, its number of lines, the child's peak RSS in MB and
 * its wall time in seconds. */
typedef struct tu_run_opts { long fsize_limit; int umask; int timeout_s; } tu_run_opts;
typedef struct tu_run_result { int lines; double max_rss_mb, seconds; } tu_run_result;
int tu_run_cli_ex(const char *const *args, const tu_run_opts *opts, char *err_all, size_t n, tu_run_result *res);
/* The Quad in code (as ../shared/scenes/quad): a 20x20 ground at y = 0 (two triangles), a 4x4 occluder
 * at y = 2, a 2x2 light at y = 6, a 96x96 camera, 1024 samples. ms_scene_free frees it. */
void tu_make_quad(ms_scene *sc);
/* Writes the scene file text as dir/scene.json and loads it into sc (paths in it are relative to dir); fails the
 * test when it does not load. */
void tu_load_scene_text(const char *dir, const char *text, ms_scene *sc);
/* 1 if ../shared/scenes is present; prints a skip message otherwise. */
int tu_have_shared_scenes(void);
/* Loads the shared scene at rel (under ../shared/scenes) into sc; skips the test when the folder is absent, fails it
 * when the scene does not load. */
void tu_shared_scene_load(const char *rel, ms_scene *sc);
const char *tu_shared_scene(char *buf, size_t n, const char *rel);
/* Reads a PFM written by ms_write_vis into a top-row-first array (caller frees). */
float *tu_read_pfm(const char *path, int *w, int *h);

/* Two frames of the same scene, pixel by pixel. A V difference is counted in samples: |dV| times the
 * pixel's front count (the larger of the two, which agree where the hit points do). S must equal where V
 * does (same masks, same weights) and may move by a few times 1/front per differing sample. */
typedef struct tu_agreement {
    long pixels, differ, beyond_one, miss_mismatch;
    long s_differ_same_v;   /* V equal, S not */
    long s_beyond;          /* |dS| > 8 * steps / front */
    double max_steps;       /* largest |dV| in samples */
    double max_ds;
} tu_agreement;
tu_agreement tu_compare_frames(const ms_frame *a, const ms_frame *b);
/* Values of two frames of the same size that are not bit for bit equal: V, S and the front count of every
 * light's plane (the larger n_lights of the two; 0 means 1). For methods that must give raytrace's answer
 * exactly. */
long tu_frame_values_differ(const ms_frame *a, const ms_frame *b);
/* The brute-force oracle of the shadow tests: segment p + u (L - p) against triangle t (9 floats) in double
 * precision (Moller-Trumbore): 1 if it crosses t at u in [near, far] (far may be INFINITY: a ray), 0 if not, 2
 * (unsure: a float test may decide either way) within 1e-6 of an edge or of the range's ends. A segment in the
 * triangle's plane never counts. */
int tu_segment_hits(const float *t, const double p[3], const double L[3], double near, double far);

/* Internal-API helpers for tests that drive shadow methods directly on chosen points. */
struct ms_render_ctx;
struct ms_shadow_query;
struct ms_shadow_method;
struct ms_bvh;
struct ms_hit;
/* The shadow query of a primary hit at pixel (x, y), as ms_render makes it. */
void tu_query_from_hit(struct ms_shadow_query *q, const struct ms_hit *h, int x, int y);
/* The queries of a size x size frame under ctx: camera rays through the bvh primary, one query per pixel that
 * hits, in pixel order. A malloc'ed array (room for every pixel), their count in *nq; fails the test when out of
 * memory. */
struct ms_shadow_query *tu_frame_queries(const struct ms_render_ctx *ctx, int size, int *nq);
/* A frame context as ms_render sets it up: grid pattern, k x k samples, the scene's camera at W x H. */
void tu_ctx_init(struct ms_render_ctx *ctx, const ms_scene *sc, const struct ms_bvh *bvh, int W, int H, int k);
/* Switches ctx to pattern p at its k (k*k samples in all): samples per pixel and mask words as ms_render
 * sets them. */
void tu_ctx_set_pattern(struct ms_render_ctx *ctx, ms_pattern p);
/* V and S of n points by a shadow method (state from its create), through front masks and ms_resolve_vs
 * exactly as ms_render does. Returns the method's visibility result (0 ok). */
int tu_shadow_vs(const struct ms_shadow_method *m, void *state, const struct ms_render_ctx *ctx,
                 const struct ms_shadow_query *q, int n, float *v, float *s, uint64_t *counters);

/* The ISA cap of this test run: MS_TEST_ISA=scalar|avx2|avx512 in the environment of the test programs
 * (read here only: the library reads no environment), MS_ISA_AUTO when unset. Tests pass it to the
 * selection functions and run a forced SIMD variant only when tu_isa_allowed grants it, so that CI can run
 * the whole suite on the portable path (.ci/run). An unknown value aborts the test. */
ms_isa tu_isa_cap(void);
/* v scaled to unit length (v not zero). */
void tu_unit3(double v[3]);
/* ms_render_options_default with the run's ISA cap, for the tests that render whole frames. */
void tu_render_options_default(ms_render_options *o);
/* Zeroed bake options with the lightmap's size, UV set (-1: xatlas for every triangle), light samples and the
 * run's ISA cap. */
void tu_bake_options(ms_bake_options *bo, int size, int uv_set, int samples);
/* The point of triangle t of sc with barycentric weights w (of its three vertices), in space (p) and in the
 * triangle's lightmap UVs (uvs: 6 floats per triangle, as ms_lightmap.uv). */
void tu_tri_point(const ms_scene *sc, const float *uvs, size_t t, const double w[3], float p[3], double uv[2]);
/* A lightmap's irradiance (green) at (u, v) of page `page`, looked up bilinearly as an engine does, from that
 * page's texel rows only (edges clamped). */
double tu_lightmap_green(const ms_frame *f, int page, double u, double v);
/* The oracle of a bake's lookups: the irradiance (green) of the scene's light at point p (normal n, on triangle
 * tri, lightmap coordinates uv of a size x size page for the pattern's key), E_unshadowed x S with S from
 * ms_visibility_points at 256 samples. */
double tu_point_irradiance(const ms_accel *acc, const ms_scene *sc, const float p[3], const float n[3], uint32_t tri,
                           const double uv[2], int size);
int tu_isa_allowed(ms_isa isa);

/* splitmix64: small, seedable, reproducible random numbers for the randomized tests. */
typedef struct tu_rng { uint64_t s; } tu_rng;
static inline uint64_t tu_rng_next(tu_rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* ms_render with o into f, failing the test with its message. */
void tu_render_ok(const ms_scene *sc, const ms_render_options *o, ms_frame *f);
/* Every method against raytrace on one scene: renders sc with o and method raytrace into *ref (the caller
 * ms_frame_frees it), then with each method of ms_method_names() in turn, and fails the test (naming `what`,
 * the method and the count) unless every light's V, S and front count equal raytrace's at every pixel.
 * `check`, when not NULL, sees each method's frame before it is freed (per-method assertions: counters,
 * stats). o->method is left at the last method. */
typedef void (*tu_method_check)(const char *method, const ms_frame *f, const ms_frame *ref, void *user);
void tu_every_method_as_raytrace(const ms_scene *sc, ms_render_options *o, const char *what, ms_frame *ref,
                                 tu_method_check check, void *user);
/* ms_render with o, returning a copy of the frame's V (width x height floats; the caller frees it) and its
 * stats into *stats (NULL: not wanted); the frame itself freed. */
float *tu_render_vis(const ms_scene *sc, const ms_render_options *o, ms_stats *stats);
/* The stats' counter of that name, failing the test when the method has none. */
uint64_t tu_stat_counter(const ms_stats *st, const char *name);

/* The unit icosphere subdivided `levels` times: n_verts vertices on the unit sphere (3 doubles each; shared
 * vertices once, midpoints looked up per edge) and n_tris triangles (3 vertex indices each); the caller
 * jitters, scales and frees both. */
void tu_unit_icosphere(int levels, double **verts, size_t *n_verts, int **tris, size_t *n_tris);

#endif
