/* `microshadow bake SCENE.json --uv N --size S -o lightmap.exr [--png preview.png]`: a lightmap of the
 * scene's lights through ms_bake (V and S per light, the irradiance summed), written all or nothing
 * (ms_outputs_*). */
#include "microshadow.h"
#include "bake.h"
#include "bake_pages_out.h"
#include "options.h"
#ifdef MS_HAVE_MPI
#include "mpi_run.h"
#endif
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>


static void usage(FILE *f)
{
    fprintf(f,
        "usage: microshadow bake [SCENE.json] [options]\n"
        "Bakes the scene's lights (rect, disk, sphere, textured) into a lightmap (the built-in scene without\n"
        "SCENE): V and S per light and the irradiance summed over the lights, per texel of a UV set;\n"
        "triangles without that set get UVs from xatlas. SCENE may be a mesh file (.glb .gltf .obj .ply .off .stl): that\n"
        "asset alone, with its own lights or one disk light above it.\n"
        "\n"
        "  --uv N              UV set tried first: 0..%d (glTF TEXCOORD_N, assimp channel N; default 1); each\n"
        "                      object keeps the first of its sets that is a valid layout (no overlap), xatlas\n"
        "                      charts objects without one; or 'xatlas' to unwrap every mesh\n"
        "                      Kept layouts are packed island by island beside xatlas's charts (engines read\n"
        "                      the glb's TEXCOORD_1), unless the file's UVs serve as they are\n"
        "  --uv-regions        move each kept layout whole into a rectangle of its own instead: one scale-offset\n"
        "                      per object (Unity's lightmapScaleOffset), pages far less full\n"
        "  --uv-islands        pack island by island even where the file's UVs would serve as they are\n"
        "  --size N            lightmap width and height in texels (default 1024)\n"
        "  -o OUT.exr          channels R, G, B (irradiance), S and V (default lightmap.exr);\n"
        "                      several lights: S0, S1, ..., V0, V1, ... (one per light)\n"
        "  --vis OUT.pfm|.exr  float V (several lights: an .exr has V0, V1, ..., a .pfm light 0)\n"
        "  --shadow OUT.pfm|.exr  float S, likewise\n"
        "  --png OUT.png       tone-mapped preview\n"
        "  --gltf OUT.glb      the scene's meshes and materials with TEXCOORD_1 = the baked UVs, the lightmap\n"
        "                      (MOZ_lightmap: linear 8-bit, intensity = its scale) and the shadowmask (S of\n"
        "                      lights 0-3 in R, G, B, A; the materials' extras name them), one binary glTF\n"
        "  --stats OUT.json    timings and counters\n"
        "  --dilate N          texels of dilation around charts (default 4; 0: none)\n"
        "  --padding N         texels between charts and regions (default 0: touching, never sharing a texel;\n"
        "                      2 or more where an engine mipmaps or block-compresses the lightmap)\n"
        "  --no-leak-fix       keep the points of texels whose centre lies inside geometry\n"
        "  --texel-density T   texels per world unit (times each mesh's \"lightmap\" scale), on as many\n"
        "                      --size pages as it takes: page p > 0 of each image output is written with .p\n"
        "                      before its ending (lightmap.exr, lightmap.1.exr, ...); default: one page\n"
        "  --uv-cache FILE     the unwrap cache: its UVs are used when it was made for this geometry and these\n"
        "                      UV options (no unwrap; other lights and samples are fine), and it is written\n"
        "                      with the outputs (default: the -o path with .uvcache for .exr)\n"
        "  --no-uv-cache       neither read nor write an unwrap cache\n"
        "  --no-seam-stitch    keep the baked texels along UV seams (default: stitched by least squares so that\n"
        "                      bilinear lookups from both sides of a seam on a smooth surface agree)\n"
        "  --method M, --pattern P, --samples N, --seed S, --threads T, --isa I, --max-memory SIZE   as for frames\n"
        "  --quiet             no progress or summary on stderr\n"
        "  --verbose           every warning in full (e.g. each unusable material file or texture)\n"
#ifdef MS_HAVE_MPI
        "  --mpi-schedule S    under mpirun: counter (default), queue or static (see microshadow --help)\n"
        "  --mpi-chunk N       under mpirun: texel rows per hand-out (default 8)\n"
#endif
        "  --help\n", MS_MAX_UV_SETS - 1);
}

/* Within the lights' pass: a percentage on the terminal, overwritten by the pass's own line at its end. */
static int progress_bar(void *user, double frac)
{
    int *last = user;
    int pct = (int)(frac * 100.0);
    if (pct != *last && pct < 100) {
        *last = pct;
        fprintf(stderr, "\rbake: lights %3d%%", pct);
        fflush(stderr);
    }
    return 0;
}

/* One line per pass of the bake (ms_bake_options.pass). */
static void pass_line(void *user, const char *pass, double seconds)
{
    (void)user;
    fprintf(stderr, "\r\033[Kbake: %s: %.3f s\n", pass, seconds);
    fflush(stderr);
}

static void pass_line_plain(void *user, const char *pass, double seconds)
{
    (void)user;
    fprintf(stderr, "bake: %s: %.3f s\n", pass, seconds);
}

enum { O_UV = 256, O_SIZE, O_PNG, O_STATS, O_VIS, O_SHADOW, O_DILATE, O_PADDING, O_METHOD, O_PATTERN, O_SAMPLES, O_SEED,
       O_THREADS, O_ISA, O_QUIET, O_HELP, O_MPI_SCHEDULE, O_MPI_CHUNK, O_VERBOSE, O_MAX_MEMORY, O_GLTF, O_NO_LEAK_FIX,
       O_NO_SEAM_STITCH, O_TEXEL_DENSITY, O_UV_CACHE, O_NO_UV_CACHE, O_UV_ISLANDS, O_UV_REGIONS };
static const struct option longopts[] = {
    { "uv", required_argument, 0, O_UV }, { "size", required_argument, 0, O_SIZE },
    { "png", required_argument, 0, O_PNG }, { "stats", required_argument, 0, O_STATS },
    { "vis", required_argument, 0, O_VIS }, { "shadow", required_argument, 0, O_SHADOW },
    { "dilate", required_argument, 0, O_DILATE }, { "padding", required_argument, 0, O_PADDING },
    { "method", required_argument, 0, O_METHOD }, { "pattern", required_argument, 0, O_PATTERN },
    { "samples", required_argument, 0, O_SAMPLES }, { "seed", required_argument, 0, O_SEED },
    { "threads", required_argument, 0, O_THREADS }, { "isa", required_argument, 0, O_ISA },
    { "quiet", no_argument, 0, O_QUIET }, { "help", no_argument, 0, O_HELP },
    { "verbose", no_argument, 0, O_VERBOSE }, { "max-memory", required_argument, 0, O_MAX_MEMORY },
    { "gltf", required_argument, 0, O_GLTF }, { "no-leak-fix", no_argument, 0, O_NO_LEAK_FIX },
    { "no-seam-stitch", no_argument, 0, O_NO_SEAM_STITCH },
    { "texel-density", required_argument, 0, O_TEXEL_DENSITY }, { "uv-cache", required_argument, 0, O_UV_CACHE },
    { "no-uv-cache", no_argument, 0, O_NO_UV_CACHE }, { "uv-islands", no_argument, 0, O_UV_ISLANDS },
    { "uv-regions", no_argument, 0, O_UV_REGIONS },
#ifdef MS_HAVE_MPI
    { "mpi-schedule", required_argument, 0, O_MPI_SCHEDULE }, { "mpi-chunk", required_argument, 0, O_MPI_CHUNK },
#endif
    { 0, 0, 0, 0 } };

/* What `microshadow bake`'s command line asks for. */
typedef struct bake_request {
    ms_bake_options bo;
    ms_output outs[MS_MAX_OUTPUTS];   /* the N_OUTS outputs, then room for the pages' (bake_pages_out.c) */
    int quiet, no_uv_cache;
#ifdef MS_HAVE_MPI
    ms_mpi_schedule schedule;
    int chunk;
#endif
} bake_request;
enum { OUT_EXR, OUT_PNG, OUT_STATS, OUT_VIS, OUT_SHADOW, OUT_GLTF, OUT_UV_CACHE, N_OUTS };

static const char *const exr_suffix[] = { ".exr", NULL };
static const char *const png_suffix[] = { ".png", NULL };
static const char *const json_suffix[] = { ".json", NULL };
static const char *const glb_suffix[] = { ".glb", NULL };

static void request_init(bake_request *r)
{
    memset(r, 0, sizeof *r);
    const ms_output outs[N_OUTS] = {
        { "-o", "lightmap.exr", ms_exr_write_stream, exr_suffix, NULL, 0 },
        { "--png", NULL, ms_png_write_stream, png_suffix, NULL, 0 },
        { "--stats", NULL, ms_stats_write_stream, json_suffix, NULL, 0 },
        { "--vis", NULL, ms_vis_write_stream, ms_float_image_suffixes, NULL, 0 },
        { "--shadow", NULL, ms_shadow_write_stream, ms_float_image_suffixes, NULL, 0 },
        /* the glb is made whole after the bake (it needs the scene and the lightmap, which a writer is not
         * given), then written with the others, all or nothing */
        { "--gltf", NULL, NULL, glb_suffix, NULL, 0 },
        { "--uv-cache", NULL, ms_bake_uv_cache_write, NULL, NULL, 0 },
    };
    memcpy(r->outs, outs, sizeof outs);
    r->bo.uv_set = 1;
    r->bo.size = 1024;
#ifdef MS_HAVE_MPI
    r->schedule = MS_MPI_COUNTER;   /* balanced best (docs/mpi.md) */
    r->chunk = 8;
#endif
}

/* Option c of `microshadow bake` (its argument in optarg) into r: -1 to go on, else the exit code (0 once --help
 * is done). */
static int take_option(bake_request *r, ms_cli_parser *cli, int c)
{
    long v;
    switch (c) {
    case O_UV:
        if (!strcmp(optarg, "xatlas")) r->bo.uv_set = -1;
        else if (ms_cli_parse_long(cli, "--uv", optarg, 0, MS_MAX_UV_SETS - 1, &v)) return EXIT_BAD_INPUT;
        else r->bo.uv_set = (int)v;
        break;
    case O_SIZE: if (ms_cli_parse_long(cli, "--size", optarg, 1, MS_MAX_IMAGE_SIZE, &v)) return EXIT_BAD_INPUT; r->bo.size = (int)v; break;
    case O_DILATE: if (ms_cli_parse_long(cli, "--dilate", optarg, 0, 1 << 16, &v)) return EXIT_BAD_INPUT; r->bo.dilate = v ? (int)v : -1; break;
    case O_PADDING: if (ms_cli_parse_long(cli, "--padding", optarg, 0, 256, &v)) return EXIT_BAD_INPUT; r->bo.padding = (int)v; break;
    case O_METHOD: r->bo.points.method = optarg; break;
    case O_PATTERN:
        if (!strcmp(optarg, "grid")) r->bo.points.pattern = MS_PATTERN_GRID;
        else if (!strcmp(optarg, "stratified")) r->bo.points.pattern = MS_PATTERN_STRATIFIED;
        else { fprintf(stderr, "microshadow bake: --pattern: '%s' is not grid or stratified\n", optarg); return EXIT_BAD_INPUT; }
        break;
    case O_SAMPLES:
        if (ms_cli_parse_long(cli, "--samples", optarg, 1, 1 << 20, &v)) return EXIT_BAD_INPUT;
        if (v != 256 && v != 1024 && v != 4096) {
            fprintf(stderr, "microshadow bake: --samples: %ld is not one of 256, 1024, 4096\n", v);
            return EXIT_BAD_INPUT;
        }
        r->bo.points.samples = (int)v;
        break;
    case O_SEED: if (ms_cli_parse_long(cli, "--seed", optarg, 0, UINT32_MAX, &v)) return EXIT_BAD_INPUT; r->bo.points.seed = (uint32_t)v; break;
    case O_THREADS: if (ms_cli_parse_long(cli, "--threads", optarg, 1, 4096, &v)) return EXIT_BAD_INPUT; r->bo.points.threads = (int)v; break;
    case O_ISA:
        if (ms_isa_from_name(optarg, &r->bo.points.isa)) {
            fprintf(stderr, "microshadow bake: --isa: '%s' is not auto, avx512, avx2 or scalar\n", optarg);
            return EXIT_BAD_INPUT;
        }
        break;
    case 'o': r->outs[OUT_EXR].path = optarg; break;
    case O_PNG: r->outs[OUT_PNG].path = optarg; break;
    case O_STATS: r->outs[OUT_STATS].path = optarg; break;
    case O_VIS: r->outs[OUT_VIS].path = optarg; break;
    case O_SHADOW: r->outs[OUT_SHADOW].path = optarg; break;
    case O_GLTF: r->outs[OUT_GLTF].path = optarg; break;
    case O_NO_LEAK_FIX: r->bo.no_leak_fix = 1; break;
    case O_NO_SEAM_STITCH: r->bo.no_seam_stitch = 1; break;
    case O_TEXEL_DENSITY: {
        char *end;
        errno = 0;
        const double d = strtod(optarg, &end);
        if (errno || end == optarg || *end || !(d > 0.0) || d > 1e9) {
            fprintf(stderr, "microshadow bake: --texel-density: '%s' is not a number of texels per world unit in (0, 1e9]\n", optarg);
            return EXIT_BAD_INPUT;
        }
        r->bo.texel_density = (float)d;
        break;
    }
    case O_UV_CACHE: r->outs[OUT_UV_CACHE].path = optarg; break;
    case O_NO_UV_CACHE: r->no_uv_cache = 1; break;
    case O_UV_ISLANDS: r->bo.uv_packing = MS_UV_PACK_ISLANDS; break;
    case O_UV_REGIONS: r->bo.uv_packing = MS_UV_PACK_REGIONS; break;
    case O_QUIET: r->quiet = 1; break;
    case O_MAX_MEMORY: if (ms_cli_parse_size(cli, "--max-memory", optarg, &r->bo.points.max_memory)) return EXIT_BAD_INPUT; break;
    case O_VERBOSE: ms_set_warning_verbose(1); break;
#ifdef MS_HAVE_MPI
    case O_MPI_SCHEDULE:
        if (ms_mpi_schedule_from_name(optarg, &r->schedule)) {
            fprintf(stderr, "microshadow bake: --mpi-r->schedule: '%s' is not queue, counter or static\n", optarg);
            return EXIT_BAD_INPUT;
        }
        break;
    case O_MPI_CHUNK: if (ms_cli_parse_long(cli, "--mpi-r->chunk", optarg, 1, MS_MAX_IMAGE_SIZE, &v)) return EXIT_BAD_INPUT; r->chunk = (int)v; break;
#endif
    case 'h': case O_HELP: usage(stdout); return 0;
    default: return EXIT_BAD_INPUT;   /* ms_cli_next said why */
    }
    return -1;
}

/* The bake's summary on stderr: what was not baked, the UVs, the pages, the texels, the shadow pass, the seams. */
static void report(const ms_bake_options *bo, const ms_output *outs, const ms_lightmap *lm, const char *what)
{
    const ms_stats *s = &lm->frame.stats;
    const int nl = lm->frame.n_lights > 1 ? lm->frame.n_lights : 1;
    char stitched[96];
    if (bo->no_seam_stitch) snprintf(stitched, sizeof stitched, "not stitched");
    else snprintf(stitched, sizeof stitched, "stitched: %zu texels in %.3fs", lm->stitched_texels, lm->stitch_s);
    if (lm->excluded_tris || lm->unbaked_tris)   /* each reason other than "lightmap": false was a warning */
        fprintf(stderr, "bake: %zu triangles not baked: %zu of meshes with \"lightmap\": false, %zu for the reasons "
                "warned about\n", lm->excluded_tris + lm->unbaked_tris, lm->excluded_tris, lm->unbaked_tris);
    char uvs[160], pages[200];
    size_t kept = 0, whole = 0;   /* objects in their own UVs; of them, moved whole (a scale-offset) */
    for (size_t o = 0; o < lm->n_objects; o++) {
        kept += lm->object_uv_set[o] >= 0;
        whole += lm->object_uv_set[o] >= 0 && lm->object_scale_offset && lm->object_scale_offset[4 * o] != 0.0f;
    }
    if (lm->uv_cached) snprintf(uvs, sizeof uvs, "UVs from %s in %.3fs", bo->uv_cache, lm->unwrap_s);
    else snprintf(uvs, sizeof uvs, "%zu objects in their own UVs%s, %zu triangles unwrapped by xatlas into %zu charts in %.3fs",
                  kept, whole < kept ? " (islands packed one by one)" : "", lm->unwrapped_tris, lm->charts,
                  lm->unwrap_s);
    int at = snprintf(pages, sizeof pages, "%d page%s, texel centres on triangles", lm->pages, lm->pages > 1 ? "s" : "");
    for (int p = 0; p < lm->pages && lm->page_fill && at < (int)sizeof pages - 16; p++)
        at += snprintf(pages + at, sizeof pages - (size_t)at, "%s %.1f%%", p ? "," : "", 100.0 * lm->page_fill[p]);
    if (lm->pages > 12) snprintf(pages + at, sizeof pages - (size_t)at, " ...");
    fprintf(stderr, "%s: %zu triangles (%s), %dx%d lightmap (%s), %zu texels on triangles "
            "(rasterized in %.3fs; %zu inside geometry moved out), %d light%s, %d samples, method %s, %d threads: shadow %.3fs "
            "(%.0f texels/s), total %.3fs; seams: %zu points, mean %.4f, p99 %.4f, max %.4f of the largest irradiance (%s) -> "
            "%s%s%s\n",
            what, s->triangles, uvs, lm->frame.width, lm->frame.width, pages, lm->texels, lm->raster_s, lm->texels_moved, nl, nl > 1 ? "s" : "", s->samples, s->method, s->threads,
            s->shadow_s, s->shadow_s > 0 ? (double)lm->texels / s->shadow_s : 0.0, s->total_s, lm->seam_points, lm->seam_mean,
            lm->seam_p99, lm->seam_max, stitched, outs[OUT_EXR].path, outs[OUT_GLTF].path ? ", " : "", outs[OUT_GLTF].path ? outs[OUT_GLTF].path : "");
}

int ms_cli_bake(int argc, char **argv)
{
    bake_request r;
    request_init(&r);
    int n_outs = N_OUTS, c;
    char *uv_cache_default = NULL;
    ms_cli_parser cli;
    ms_cli_parser_init(&cli, "microshadow bake", longopts);
    while ((c = ms_cli_next(&cli, argc, argv)) != -1) {
        const int rc = take_option(&r, &cli, c);
        if (rc >= 0) return rc;
    }
    if (argc - optind > 1) { fprintf(stderr, "microshadow bake: more than one scene file given\n"); return EXIT_BAD_INPUT; }
    const char *scene_path = optind < argc ? argv[optind] : NULL;
    const char *method = r.bo.points.method ? r.bo.points.method : MS_DEFAULT_METHOD;
    if (ms_cli_check_method(&cli, method)) return EXIT_BAD_INPUT;
    char err[1024];
    ms_outputs_cleanup_on_signals();
    if (r.no_uv_cache) r.outs[OUT_UV_CACHE].path = NULL;
    else if (!r.outs[OUT_UV_CACHE].path) {   /* the cache beside the lightmap, where a re-bake of the same command finds it */
        if (!(uv_cache_default = ms_bake_uv_cache_default(r.outs[OUT_EXR].path))) { fprintf(stderr, "microshadow bake: out of memory\n"); return EXIT_NO_MEMORY; }
        r.outs[OUT_UV_CACHE].path = uv_cache_default;
    }
    r.bo.uv_cache = r.outs[OUT_UV_CACHE].path;
    if (ms_outputs_check(r.outs, N_OUTS, err, sizeof err)) {
        fprintf(stderr, "microshadow bake: %s\n", err);
        free(uv_cache_default);
        return EXIT_BAD_INPUT;
    }
    ms_scene scene;
    if (scene_path) {
        const ms_status lst = ms_scene_load(scene_path, &scene, err, sizeof err);
        if (lst) { fprintf(stderr, "microshadow bake: %s\n", err); free(uv_cache_default); return ms_cli_exit_code(lst); }
    } else if (ms_scene_default(&scene)) {
        fprintf(stderr, "microshadow bake: out of memory building the built-in scene\n");
        return EXIT_NO_MEMORY;
    }
    int last = -1;
    ms_lightmap lm;
    ms_status st = MS_OK;
#ifdef MS_HAVE_MPI
    if (ms_mpi_active()) {
        /* Every rank bakes its rows; rank 0 alone writes (mpi_bake.c). */
        r.outs[OUT_STATS].write = ms_mpi_stats_write_stream;
        const int mrc = ms_mpi_bake(&scene, scene_path ? scene_path : "built-in scene", &r.bo, r.schedule, r.chunk, &lm, err, sizeof err);
        if (mrc || ms_mpi_rank() != 0) {
            ms_scene_free(&scene);
            free(uv_cache_default);
            return mrc ? EXIT_BAD_INPUT : 0;
        }
    } else
#endif
    {
        if (!r.quiet && isatty(STDERR_FILENO)) {
            r.bo.points.progress = progress_bar;
            r.bo.points.progress_user = &last;
            r.bo.pass = pass_line;
        } else if (!r.quiet)
            r.bo.pass = pass_line_plain;
        st = ms_bake(&scene, NULL, &r.bo, &lm, err, sizeof err);
    }
    if (st) {
        fprintf(stderr, "microshadow bake: %s: %s\n", scene_path ? scene_path : "built-in scene", err);
        ms_scene_free(&scene);
        free(uv_cache_default);
        return ms_cli_exit_code(st);
    }
    unsigned char *glb = NULL;
    int rc = 0;
    if (r.outs[OUT_GLTF].path) {
        size_t len = 0;
        st = ms_bake_gltf(&scene, &lm, NULL, &glb, &len, err, sizeof err);
        if (st) {
            fprintf(stderr, "microshadow bake: %s: %s\n", r.outs[OUT_GLTF].path, err);
            rc = ms_cli_exit_code(st);
        }
        r.outs[OUT_GLTF].bytes = glb;
        r.outs[OUT_GLTF].n_bytes = len;
    }
    ms_bake_uv_cache_source(&lm);
    if (!rc && (ms_bake_pages_out(&lm, r.outs, &n_outs, err, sizeof err) || ms_outputs_check(r.outs, n_outs, err, sizeof err))) {
        fprintf(stderr, "microshadow bake: %s\n", err);
        rc = EXIT_BAD_INPUT;
    }
    if (!rc) {
        rc = ms_cli_exit_code(ms_outputs_write(&lm.frame, r.outs, n_outs, err, sizeof err));
        if (rc) fprintf(stderr, "microshadow bake: %s\n", err);
    }
    ms_bake_pages_out_free();
    free(glb);
    if (!r.quiet && !rc) report(&r.bo, r.outs, &lm, scene_path ? scene_path : "built-in scene");
    ms_lightmap_free(&lm);
    ms_scene_free(&scene);
    free(uv_cache_default);
    return rc;
}
