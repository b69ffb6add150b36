/* The microshadow command line: render a scene file (or the built-in scene) with one shadow method. */
#include "microshadow.h"
#include "bake.h"
#include "options.h"
#ifdef MS_HAVE_MPI
#include "mpi_run.h"
#endif
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* --aa when neither it nor the scene's render.aa is given (docs/antialiasing.md: the measured cost). */
#define MS_CLI_AA_DEFAULT 4

static void usage(FILE *f)
{
    fprintf(f,
        "usage: microshadow [SCENE.json] [options]\n"
        "       microshadow bake [SCENE.json] [options]   (a lightmap: microshadow bake --help)\n"
        "Renders soft shadows from the scene's area lights (rect, disk, sphere, triangle, sun, textured; the meshes' own emitters and glTF punctual lights when the scene file names none; the built-in scene without SCENE).\n"
        "SCENE may be a mesh file (.glb .gltf .obj .ply .off .stl): that asset alone, with its own lights and camera or a\n"
        "camera looking at it and one disk light above it.\n"
        "\n"
        "  --method M          shadow method:");
    for (const char *const *m = ms_method_names(); *m; m++) fprintf(f, " %s", *m);
    fprintf(f,
        " (default scanline),\n"
        "                      or auto: the one measured fastest for the pattern and scene (docs/methods.md)\n"
        "  --pattern P         light samples: grid (default), stratified, or interleaved (N/16 per pixel\n"
        "                      of a 4x4 block, then a 4x4 depth- and normal-aware filter; ray tracers only)\n"
        "  --samples N         256, 1024 or 4096 light samples (default: the scene's); stratified also 16, 64\n"
        "  --no-filter         interleaved: raw per-pixel V and S, without the filter\n"
        "  --width W, --height H   image size (default: the scene camera's)\n"
        "  --aa K              anti-aliasing: K = 1, 4, 9 or 16 primary samples per pixel, each with its own\n"
        "                      shadow query; the pixel is their average (default: the scene's render.aa,\n"
        "                      else %d; 1 when --vis or --shadow asks for the sample-for-sample planes)\n"
        "  --aa-split          with --aa K: the pixel's N light samples split among its K primary samples\n"
        "                      (N/K each) instead of N for each\n"
        "  --threads T         threads (default: all cores)\n"
        "  --seed S            seed of the per-pixel sample patterns (default 0)\n"
        "  -o OUT.png|.exr     shaded image (default microshadow.png): PNG tone-mapped sRGB, EXR linear HDR\n"
        "                      radiance (channels R, G, B, V, S; several lights: V0, V1, ..., S0, S1, ...)\n"
        "  --shading S         standard (default: the materials, diffuse and specular) or diffuse (base colour\n"
        "                      x irradiance x S / pi alone: what a baked lightmap can show, to compare with\n"
        "                      the viewer of `microshadow bake --gltf`)\n"
        "  --exposure EV       PNG: stops added to the automatic exposure (which maps the 99th percentile of\n"
        "                      unshadowed radiance to 1): the PNG shows radiance * 2^EV * auto (default 0)\n"
        "  --vis OUT.pfm|.exr  float visibility V, -1 where the primary ray missed\n"
        "  --shadow OUT.pfm|.exr  float shadow factor S, -1 where the primary ray missed\n"
        "                      (several lights: an .exr has channels V0, V1, ... resp. S0, S1, ..., a .pfm light 0)\n"
        "  --stats OUT.json    timings and counters\n"
        "  --isa I             cap on the SIMD instruction set: auto (default), avx512, avx2, scalar\n"
        "  --traversal T       micro-raster methods: block (default: 4x4 pixels' frusta together) or pixel\n"
        "  --frustum-shrink    block traversal and mft: narrow each frustum as its samples are occluded\n"
        "  --primary P         primary visibility: bvh, embree, 3dr-bb, 3dr-bin, 3dr-fc, 3dr-fs, 3dr-full,\n"
        "                      depth (default: the method's pairing; docs/primary.md)\n"
        "  --consistent        bvh primary: the 3D rasterizers' consistent edge test (same hits as 3dr-*)\n"
        "  --closed-cull on|off  leave out the side of closed meshes facing away from the light (the same\n"
        "                      answer, docs/culling.md); default: on for the micro-raster methods\n"
        "  --no-interior       micro-raster methods: no interior boxes (docs/culling.md; to measure)\n"
        "  --no-merge          micro-raster methods: do not merge coplanar rectangles (docs/culling.md)\n"
        "  --embree-mode M     embree method: packet16 (default: rtcOccluded16), packet8 or stream (docs/embree.md)\n"
        "  --embree-filter F   embree method: when the receiver's triangle is filtered out: plane (default),\n"
        "                      always, none (to measure only: the receiver then shadows itself)\n"
        "  --max-memory SIZE   memory budget (e.g. 512M, 8G; default %d%% of physical memory): a frame that\n"
        "                      would need more is refused before anything is allocated, naming what fits\n"
        "  --stream            write the outputs as the rows finish, holding one band of rows in memory (the\n"
        "                      default when only that fits the memory budget; docs/memory.md)\n"
        "  --no-stream         hold the whole frame, never stream\n"
        "  --quiet             no progress or summary on stderr\n"
        "  --verbose           every warning in full (e.g. each unusable material file or texture, which\n"
        "                      are otherwise one line per scene: their number and the first)\n"
#ifdef MS_HAVE_MPI
        "  --mpi-schedule S    under mpirun: how ranks get tiles: counter (default: a shared counter, MPI\n"
        "                      one-sided), queue (rank 0 hands them out), static (round robin)\n"
        "  --mpi-chunk N       under mpirun: tiles per hand-out (default: --threads, or 4)\n"
#endif
        "  --help, --version\n", MS_CLI_AA_DEFAULT, MS_MEMORY_DEFAULT_PERCENT);
}

static int progress_bar(void *user, double frac)
{
    int *last = user;
    int pct = (int)(frac * 100.0);
    if (pct == *last) return 0;
    *last = pct;
    int filled = pct * 40 / 100;
    char bar[41];
    for (int i = 0; i < 40; i++) bar[i] = i < filled ? '#' : '.';
    bar[40] = 0;
    fprintf(stderr, "\r[%s] %3d%%", bar, pct);
    if (pct >= 100) fputc('\n', stderr);
    fflush(stderr);
    return 0;
}

enum { O_METHOD = 256, O_PATTERN, O_SAMPLES, O_WIDTH, O_HEIGHT, O_THREADS, O_SEED, O_VIS, O_SHADOW,
       O_STATS, O_ISA, O_TRAVERSAL, O_FRUSTUM_SHRINK, O_QUIET, O_HELP, O_VERSION, O_NO_FILTER,
       O_EXPOSURE, O_MPI_SCHEDULE, O_MPI_CHUNK, O_VERBOSE, O_PRIMARY, O_CONSISTENT, O_CLOSED_CULL, O_NO_INTERIOR, O_NO_MERGE, O_MAX_MEMORY,
       O_EMBREE_MODE, O_EMBREE_FILTER, O_STREAM, O_NO_STREAM, O_AA, O_AA_SPLIT, O_SHADING };
static const struct option longopts[] = {
    { "method", required_argument, 0, O_METHOD }, { "pattern", required_argument, 0, O_PATTERN },
    { "samples", required_argument, 0, O_SAMPLES }, { "width", required_argument, 0, O_WIDTH },
    { "height", required_argument, 0, O_HEIGHT }, { "threads", required_argument, 0, O_THREADS },
    { "seed", required_argument, 0, O_SEED }, { "vis", required_argument, 0, O_VIS },
    { "shadow", required_argument, 0, O_SHADOW }, { "isa", required_argument, 0, O_ISA },
    { "stats", required_argument, 0, O_STATS }, { "quiet", no_argument, 0, O_QUIET },
    { "verbose", no_argument, 0, O_VERBOSE },
    { "traversal", required_argument, 0, O_TRAVERSAL }, { "frustum-shrink", no_argument, 0, O_FRUSTUM_SHRINK },
    { "no-filter", no_argument, 0, O_NO_FILTER }, { "help", no_argument, 0, O_HELP }, { "version", no_argument, 0, O_VERSION },
    { "exposure", required_argument, 0, O_EXPOSURE }, { "primary", required_argument, 0, O_PRIMARY },
    { "consistent", no_argument, 0, O_CONSISTENT },
    { "closed-cull", required_argument, 0, O_CLOSED_CULL },
    { "no-interior", no_argument, 0, O_NO_INTERIOR },
    { "no-merge", no_argument, 0, O_NO_MERGE },
    { "max-memory", required_argument, 0, O_MAX_MEMORY },
    { "embree-mode", required_argument, 0, O_EMBREE_MODE }, { "embree-filter", required_argument, 0, O_EMBREE_FILTER },
    { "stream", no_argument, 0, O_STREAM }, { "no-stream", no_argument, 0, O_NO_STREAM },
    { "aa", required_argument, 0, O_AA }, { "aa-split", no_argument, 0, O_AA_SPLIT },
    { "shading", required_argument, 0, O_SHADING },
#ifdef MS_HAVE_MPI
    { "mpi-schedule", required_argument, 0, O_MPI_SCHEDULE }, { "mpi-chunk", required_argument, 0, O_MPI_CHUNK },
#endif
    { 0, 0, 0, 0 } };
enum { OUT_PNG, OUT_VIS, OUT_SHADOW, OUT_STATS, N_OUTS };

/* What the command line asks for. */
typedef struct cli_request {
    ms_render_options opt;
    /* Every output the command line can ask for: one row each, checked before the render and written
     * all or nothing after it (ms_outputs_check, ms_outputs_write). */
    ms_output outs[N_OUTS];
    int quiet;
    double exposure_ev;   /* --exposure: stops on top of the automatic exposure (PNG only) */
#ifdef MS_HAVE_MPI
    ms_mpi_schedule schedule;
    int chunk;
#endif
} cli_request;

/* A name whose ending the CLI does not write (out.jpg, out.tiff, no ending) is refused, not written as PNG bytes
 * under that name. */
static const char *const image_suffixes[] = { ".png", ".exr", NULL };
static const char *const json_suffix[] = { ".json", NULL };

static void request_init(cli_request *r)
{
    memset(r, 0, sizeof *r);
    ms_render_options_default(&r->opt);
    const ms_output outs[N_OUTS] = {
        { "-o", "microshadow.png", ms_png_write_stream, image_suffixes, NULL, 0 },
        { "--vis", NULL, ms_vis_write_stream, ms_float_image_suffixes, NULL, 0 },
        { "--shadow", NULL, ms_shadow_write_stream, ms_float_image_suffixes, NULL, 0 },
        { "--stats", NULL, ms_stats_write_stream, json_suffix, NULL, 0 },
    };
    memcpy(r->outs, outs, sizeof outs);
#ifdef MS_HAVE_MPI
    r->schedule = MS_MPI_COUNTER;   /* balanced best (docs/mpi.md) */
#endif
}

/* Option c of the command line (its argument in optarg) into r: -1 to go on, else the exit code (0 once --help
 * or --version is done). */
static int take_option(cli_request *r, ms_cli_parser *cli, int c)
{
    long v;
    switch (c) {
    case O_METHOD: r->opt.method = optarg; break;
    case O_PATTERN:
        if (ms_pattern_from_name(optarg, &r->opt.pattern)) {
            fprintf(stderr, "microshadow: --pattern: '%s' is not grid, stratified or interleaved\n", optarg);
            return EXIT_BAD_INPUT;
        }
        break;
    case O_SAMPLES:
        if (ms_cli_parse_long(cli, "--samples", optarg, 1, 1 << 20, &v)) return EXIT_BAD_INPUT;
        if (v != 16 && v != 64 && v != 256 && v != 1024 && v != 4096) {
            fprintf(stderr, "microshadow: --samples: %ld is not one of 16, 64, 256, 1024, 4096\n", v);
            return EXIT_BAD_INPUT;
        }
        r->opt.samples = (int)v;
        break;
    case O_WIDTH: if (ms_cli_parse_long(cli, "--width", optarg, 1, MS_MAX_IMAGE_SIZE, &v)) return EXIT_BAD_INPUT; r->opt.width = (int)v; break;
    case O_HEIGHT: if (ms_cli_parse_long(cli, "--height", optarg, 1, MS_MAX_IMAGE_SIZE, &v)) return EXIT_BAD_INPUT; r->opt.height = (int)v; break;
    case O_THREADS: if (ms_cli_parse_long(cli, "--threads", optarg, 1, 4096, &v)) return EXIT_BAD_INPUT; r->opt.threads = (int)v; break;
    case O_SEED: if (ms_cli_parse_long(cli, "--seed", optarg, 0, UINT32_MAX, &v)) return EXIT_BAD_INPUT; r->opt.seed = (uint32_t)v; break;
    case 'o': r->outs[OUT_PNG].path = optarg; break;
    case O_VIS: r->outs[OUT_VIS].path = optarg; break;
    case O_SHADOW: r->outs[OUT_SHADOW].path = optarg; break;
    case O_ISA:
        if (ms_isa_from_name(optarg, &r->opt.isa)) {
            fprintf(stderr, "microshadow: --isa: '%s' is not auto, avx512, avx2 or scalar\n", optarg);
            return EXIT_BAD_INPUT;
        }
        break;
    case O_TRAVERSAL:
        if (strcmp(optarg, "block") == 0) r->opt.traversal = MS_TRAVERSAL_BLOCK;
        else if (strcmp(optarg, "pixel") == 0) r->opt.traversal = MS_TRAVERSAL_PIXEL;
        else { fprintf(stderr, "microshadow: --traversal: '%s' is not block or pixel\n", optarg); return EXIT_BAD_INPUT; }
        break;
    case O_FRUSTUM_SHRINK: r->opt.frustum_shrink = 1; break;
    case O_STATS: r->outs[OUT_STATS].path = optarg; break;
    case O_QUIET: r->quiet = 1; break;
    case O_VERBOSE: ms_set_warning_verbose(1); break;
    case O_NO_FILTER: r->opt.no_filter = 1; break;
    case O_PRIMARY: r->opt.primary = optarg; break;
    case O_CONSISTENT: r->opt.consistent_primary = 1; break;
    case O_CLOSED_CULL:
        if (!strcmp(optarg, "on")) r->opt.closed_cull = MS_CLOSED_CULL_ON;
        else if (!strcmp(optarg, "off")) r->opt.closed_cull = MS_CLOSED_CULL_OFF;
        else { fprintf(stderr, "microshadow: --closed-cull: '%s' is not on or off\n", optarg); return EXIT_BAD_INPUT; }
        break;
    case O_NO_INTERIOR: r->opt.no_interior = 1; break;
    case O_NO_MERGE: r->opt.no_merge = 1; break;
    case O_EMBREE_MODE:
        if (!strcmp(optarg, "packet16")) r->opt.embree_mode = MS_EMBREE_PACKET16;
        else if (!strcmp(optarg, "packet8")) r->opt.embree_mode = MS_EMBREE_PACKET8;
        else if (!strcmp(optarg, "stream")) r->opt.embree_mode = MS_EMBREE_STREAM;
        else { fprintf(stderr, "microshadow: --embree-mode: '%s' is not packet16, packet8 or stream\n", optarg); return EXIT_BAD_INPUT; }
        break;
    case O_EMBREE_FILTER:
        if (!strcmp(optarg, "plane")) r->opt.embree_filter = MS_EMBREE_FILTER_PLANE;
        else if (!strcmp(optarg, "always")) r->opt.embree_filter = MS_EMBREE_FILTER_ALWAYS;
        else if (!strcmp(optarg, "none")) r->opt.embree_filter = MS_EMBREE_FILTER_NONE;
        else { fprintf(stderr, "microshadow: --embree-filter: '%s' is not plane, always or none\n", optarg); return EXIT_BAD_INPUT; }
        break;
    case O_STREAM: r->opt.stream = MS_STREAM_ON; break;
    case O_NO_STREAM: r->opt.stream = MS_STREAM_OFF; break;
    case O_AA:
        if (ms_cli_parse_long(cli, "--aa", optarg, 1, 16, &v)) return EXIT_BAD_INPUT;
        if (v != 1 && v != 4 && v != 9 && v != 16) {
            fprintf(stderr, "microshadow: --aa: %ld is not one of 1, 4, 9, 16\n", v);
            return EXIT_BAD_INPUT;
        }
        r->opt.aa = (int)v;
        break;
    case O_AA_SPLIT: r->opt.aa_split = 1; break;
    case O_SHADING:
        if (!strcmp(optarg, "standard")) r->opt.shading = MS_SHADING_STANDARD;
        else if (!strcmp(optarg, "diffuse")) r->opt.shading = MS_SHADING_DIFFUSE;
        else { fprintf(stderr, "microshadow: --shading: '%s' is not standard or diffuse\n", optarg); return EXIT_BAD_INPUT; }
        break;
    case O_MAX_MEMORY: if (ms_cli_parse_size(cli, "--max-memory", optarg, &r->opt.max_memory)) return EXIT_BAD_INPUT; break;
    case O_EXPOSURE: {
        char *end;
        errno = 0;
        r->exposure_ev = strtod(optarg, &end);
        if (end == optarg || *end || errno || !(r->exposure_ev >= -64.0 && r->exposure_ev <= 64.0)) {
            fprintf(stderr, "microshadow: --exposure: '%s' is not a number of stops in [-64, 64]\n", optarg);
            return EXIT_BAD_INPUT;
        }
        break;
    }
#ifdef MS_HAVE_MPI
    case O_MPI_SCHEDULE:
        if (ms_mpi_schedule_from_name(optarg, &r->schedule)) {
            fprintf(stderr, "microshadow: --mpi-schedule: '%s' is not queue, counter or static\n", optarg);
            return EXIT_BAD_INPUT;
        }
        break;
    case O_MPI_CHUNK: if (ms_cli_parse_long(cli, "--mpi-chunk", optarg, 1, 4096, &v)) return EXIT_BAD_INPUT; r->chunk = (int)v; break;
#endif
    case 'h': case O_HELP: usage(stdout); return 0;
    case O_VERSION: printf("microshadow %s\n", MS_VERSION_STRING); return 0;
    default: return EXIT_BAD_INPUT;   /* ms_cli_next said why */
    }
    return -1;
}

static int cli_main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "bake") == 0) return ms_cli_bake(argc - 1, argv + 1);
    cli_request r;
    request_init(&r);
    int c;
    ms_cli_parser cli;
    ms_cli_parser_init(&cli, "microshadow", longopts);
    while ((c = ms_cli_next(&cli, argc, argv)) != -1) {
        const int rc = take_option(&r, &cli, c);
        if (rc >= 0) return rc;
    }
    if (argc - optind > 1) { fprintf(stderr, "microshadow: more than one scene file given\n"); return EXIT_BAD_INPUT; }
    const char *scene_path = optind < argc ? argv[optind] : NULL;
    /* -o OUT.exr: linear HDR radiance (R, G, B, with V and S) instead of the tone-mapped PNG. */
    const size_t olen = strlen(r.outs[OUT_PNG].path);
    if (olen >= 4 && !strcasecmp(r.outs[OUT_PNG].path + olen - 4, ".exr")) r.outs[OUT_PNG].write = ms_exr_write_stream;

    if (ms_cli_check_method(&cli, r.opt.method)) return EXIT_BAD_INPUT;
    char err[1024];
    /* Refuse bad outputs before a long render; from here on a signal removes any staging file. */
    ms_outputs_cleanup_on_signals();
    const ms_status cst = ms_outputs_check(r.outs, N_OUTS, err, sizeof err);
    if (cst) {
        fprintf(stderr, "microshadow: %s\n", err);
        return ms_cli_exit_code(cst);
    }

    ms_scene scene;
    if (scene_path) {
        const ms_status lst = ms_scene_load(scene_path, &scene, err, sizeof err);
        if (lst) {
            fprintf(stderr, "microshadow: %s\n", err);
            return ms_cli_exit_code(lst);
        }
    } else if (ms_scene_showcase(&scene)) {
        fprintf(stderr, "microshadow: out of memory building the built-in scene\n");
        return EXIT_NO_MEMORY;
    }
    /* Anti-aliased pictures by default; the V and S planes, which users compare method against method
     * and with other renderers sample for sample, stay one primary sample per pixel unless asked. */
    if (!r.opt.aa && !scene.aa) r.opt.aa = r.outs[OUT_VIS].path || r.outs[OUT_SHADOW].path ? 1 : MS_CLI_AA_DEFAULT;
    int last = -1;
    ms_stats stats;
    const char *what = scene_path ? scene_path : "built-in scene";
#ifdef MS_HAVE_MPI
    if (ms_mpi_active()) {
        /* Every rank renders its share; rank 0 alone writes (mpi_frame.c). */
        ms_frame frame;
        if (!r.chunk) r.chunk = r.opt.threads > 0 ? r.opt.threads : 4;
        if (r.opt.stream == MS_STREAM_ON && ms_mpi_rank() == 0)
            fprintf(stderr, "microshadow: warning: --stream is not done under mpirun (rank 0 assembles the whole frame)\n");
        r.outs[OUT_STATS].write = ms_mpi_stats_write_stream;
        const int mrc = ms_mpi_frame(&scene, what, &r.opt, r.schedule, r.chunk, &frame, err, sizeof err);
        if (mrc || ms_mpi_rank() != 0) {
            ms_frame_free(&frame);
            ms_scene_free(&scene);
            return mrc ? EXIT_BAD_INPUT : 0;
        }
        frame.exposure *= (float)exp2(r.exposure_ev);
        const ms_status wrc = ms_outputs_write(&frame, r.outs, N_OUTS, err, sizeof err);
        stats = frame.stats;
        ms_frame_free(&frame);
        if (wrc) {
            fprintf(stderr, "microshadow: %s\n", err);
            ms_scene_free(&scene);
            return ms_cli_exit_code(wrc);
        }
    } else
#endif
    {
        if (!r.quiet && isatty(STDERR_FILENO)) { r.opt.progress = progress_bar; r.opt.progress_user = &last; }
        /* Rendered and written together: streamed band by band when asked, or when only that fits the budget. */
        const ms_status rrc = ms_render_outputs(&scene, &r.opt, r.exposure_ev, r.outs, N_OUTS, &stats, err, sizeof err);
        if (rrc == MS_ERR_IO) fprintf(stderr, "microshadow: %s\n", err);
        else if (rrc) fprintf(stderr, "microshadow: %s: %s\n", what, err);
        if (rrc) {
            ms_scene_free(&scene);
            return ms_cli_exit_code(rrc);
        }
    }
    if (!r.quiet && stats.stream_rows && r.opt.stream == MS_STREAM_AUTO) {
        char nb[32], bb[32];
        snprintf(nb, sizeof nb, "%.1f MiB", (double)stats.memory_need / 1048576.0);
        snprintf(bb, sizeof bb, "%.1f MiB", (double)stats.memory_budget / 1048576.0);
        fprintf(stderr, "microshadow: the whole frame exceeds the memory budget (%s): the outputs were written as the rows "
                "finished, %d rows at a time (about %s)\n", bb, stats.stream_rows, nb);
    }
    if (!r.quiet) {
        const ms_stats *s = &stats;
        /* the lights' count too: an asset's own emitters and punctual lights become lights without a line of
         * the scene file naming them */
        size_t n_lights;
        ms_scene_lights(&scene, &n_lights);
        /* the frame's size as asked; the stats count the shading grid (aa per pixel) */
        const int aa = s->aa > 0 ? s->aa : 1, aa_s = (int)lround(sqrt((double)aa));
        fprintf(stderr, "%s: %zu triangles, %zu light%s, %dx%d (aa %d), %d samples (%s), method %s, %d threads: build %.3fs, "
                "setup %.3fs, primary %.3fs, shadow %.3fs (%.1f M shadow rays/s), total %.3fs -> %s\n",
                what, s->triangles, n_lights, n_lights == 1 ? "" : "s", s->width / aa_s, s->height / aa_s, aa, s->samples,
                s->pattern, s->method,
                s->threads, s->build_s, s->setup_s, s->primary_s, s->shadow_s,
                s->shadow_s > 0 ? (double)s->shadow_rays / s->shadow_s * 1e-6 : 0.0, s->total_s, r.outs[OUT_PNG].path);
    }
    ms_scene_free(&scene);
    return 0;
}

int main(int argc, char **argv)
{
#ifdef MS_HAVE_MPI
    /* Under mpirun: every rank runs the command line; the ranks agree on the outcome at the end. */
    if (ms_mpi_start(&argc, &argv)) return ms_mpi_end(cli_main(argc, argv));
#endif
    return cli_main(argc, argv);
}
