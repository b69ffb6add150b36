/* The microshadow command line: render a scene file (or the built-in scene) with one shadow method. */
#include "microshadow.h"
#include "image/atomic_file.h"
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define EXIT_BAD_INPUT 2

static void usage(FILE *f)
{
    fprintf(f,
        "usage: microshadow [SCENE.json] [options]\n"
        "Renders soft shadows from the scene's parallelogram light (the built-in scene without SCENE).\n"
        "\n"
        "  --method M          shadow method:");
    for (const char *const *m = ms_method_names(); *m; m++) fprintf(f, " %s", *m);
    fprintf(f,
        " (default scanline)\n"
        "  --pattern P         light samples: grid (default) or stratified\n"
        "  --samples N         256, 1024 or 4096 light samples per pixel (default: the scene's)\n"
        "  --width W, --height H   image size (default: the scene camera's)\n"
        "  --threads T         threads (default: all cores)\n"
        "  --seed S            seed of the per-pixel sample patterns (default 0)\n"
        "  -o OUT.png          shaded image (default microshadow.png)\n"
        "  --vis OUT.pfm|.exr  float visibility image, -1 where the primary ray missed\n"
        "  --stats OUT.json    timings and counters\n"
        "  --quiet             no progress or summary on stderr\n"
        "  --help, --version\n");
}

static void progress_bar(void *user, double frac)
{
    int *last = user;
    int pct = (int)(frac * 100.0);
    if (pct == *last) return;
    *last = pct;
    int filled = pct * 40 / 100;
    char bar[41];
    for (int i = 0; i < 40; i++) bar[i] = i < filled ? '#' : '.';
    bar[40] = 0;
    fprintf(stderr, "\r[%s] %3d%%", bar, pct);
    if (pct >= 100) fputc('\n', stderr);
    fflush(stderr);
}

static int parse_int(const char *opt, const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) {
        fprintf(stderr, "microshadow: %s: '%s' is not an integer in [%ld, %ld]\n", opt, s, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

/* All outputs or none: each is first written (atomically) under a staging name beside its target, and
 * only when every one succeeded are they renamed into place; a failure removes the staged files. */
static int write_outputs(const ms_frame *f, const char *png, const char *vis, const char *stats, char *err,
                         size_t errlen)
{
    const char *path[3] = { png, vis, stats };
    char staged[3][4200];
    int written = 0, rc = 0;
    for (int i = 0; i < 3 && !rc; i++) {
        if (!path[i]) continue;
        /* The staging name keeps the extension, which selects the visibility format. */
        const char *slash = strrchr(path[i], '/');
        int dir = slash ? (int)(slash - path[i] + 1) : 0;
        snprintf(staged[i], sizeof staged[i], "%.*s.ms-stage-%ld-%s", dir, path[i], (long)getpid(), path[i] + dir);
        rc = i == 0 ? ms_write_png(f, staged[i], err, errlen)
           : i == 1 ? ms_write_vis(f, staged[i], err, errlen)
                    : ms_write_stats_json(f, staged[i], err, errlen);
        if (rc) {
            /* Name the user's file in the message, not the staging one. */
            char *at = strstr(err, staged[i]);
            if (at) {
                char rest[1024];
                snprintf(rest, sizeof rest, "%s%s", path[i], at + strlen(staged[i]));
                snprintf(at, errlen - (size_t)(at - err), "%s", rest);
            }
        } else {
            written |= 1 << i;
        }
    }
    for (int i = 0; i < 3 && !rc; i++)
        if ((written >> i & 1) && rename(staged[i], path[i]) != 0) {
            snprintf(err, errlen, "%s: cannot rename into place: %s", path[i], strerror(errno));
            rc = -1;
        }
    for (int i = 0; i < 3; i++)
        if (written >> i & 1) unlink(staged[i]);   /* a no-op for those renamed */
    return rc ? EXIT_BAD_INPUT : 0;
}

int main(int argc, char **argv)
{
    enum { O_METHOD = 256, O_PATTERN, O_SAMPLES, O_WIDTH, O_HEIGHT, O_THREADS, O_SEED, O_VIS, O_STATS,
           O_QUIET, O_HELP, O_VERSION };
    static const struct option longopts[] = {
        { "method", required_argument, 0, O_METHOD }, { "pattern", required_argument, 0, O_PATTERN },
        { "samples", required_argument, 0, O_SAMPLES }, { "width", required_argument, 0, O_WIDTH },
        { "height", required_argument, 0, O_HEIGHT }, { "threads", required_argument, 0, O_THREADS },
        { "seed", required_argument, 0, O_SEED }, { "vis", required_argument, 0, O_VIS },
        { "stats", required_argument, 0, O_STATS }, { "quiet", no_argument, 0, O_QUIET },
        { "help", no_argument, 0, O_HELP }, { "version", no_argument, 0, O_VERSION }, { 0, 0, 0, 0 } };
    ms_render_options opt;
    ms_render_options_default(&opt);
    const char *out_png = "microshadow.png", *out_vis = NULL, *out_stats = NULL;
    int quiet = 0, c;
    long v;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:h", longopts, NULL)) != -1) {
        switch (c) {
        case O_METHOD: opt.method = optarg; break;
        case O_PATTERN:
            if (strcmp(optarg, "grid") == 0) opt.pattern = MS_PATTERN_GRID;
            else if (strcmp(optarg, "stratified") == 0) opt.pattern = MS_PATTERN_STRATIFIED;
            else { fprintf(stderr, "microshadow: --pattern: '%s' is not grid or stratified\n", optarg); return EXIT_BAD_INPUT; }
            break;
        case O_SAMPLES:
            if (parse_int("--samples", optarg, 1, 1 << 20, &v)) return EXIT_BAD_INPUT;
            if (v != 256 && v != 1024 && v != 4096) {
                fprintf(stderr, "microshadow: --samples: %ld is not one of 256, 1024, 4096\n", v);
                return EXIT_BAD_INPUT;
            }
            opt.samples = (int)v;
            break;
        case O_WIDTH: if (parse_int("--width", optarg, 1, 16384, &v)) return EXIT_BAD_INPUT; opt.width = (int)v; break;
        case O_HEIGHT: if (parse_int("--height", optarg, 1, 16384, &v)) return EXIT_BAD_INPUT; opt.height = (int)v; break;
        case O_THREADS: if (parse_int("--threads", optarg, 1, 4096, &v)) return EXIT_BAD_INPUT; opt.threads = (int)v; break;
        case O_SEED: if (parse_int("--seed", optarg, 0, UINT32_MAX, &v)) return EXIT_BAD_INPUT; opt.seed = (uint32_t)v; break;
        case 'o': out_png = optarg; break;
        case O_VIS: out_vis = optarg; break;
        case O_STATS: out_stats = optarg; break;
        case O_QUIET: quiet = 1; break;
        case 'h': case O_HELP: usage(stdout); return 0;
        case O_VERSION: printf("microshadow %s\n", MS_VERSION_STRING); return 0;
        default:
            /* optopt is the short option's character, or a long option's val (>= 256) when its value
             * is missing: then argv[optind - 1] names it, as it does an unknown long option. */
            if (optopt > 0 && optopt < 256) fprintf(stderr, "microshadow: option '-%c' is unknown or needs a value (see --help)\n", optopt);
            else fprintf(stderr, "microshadow: option '%s' is unknown or needs a value (see --help)\n", argv[optind - 1]);
            return EXIT_BAD_INPUT;
        }
    }
    if (argc - optind > 1) { fprintf(stderr, "microshadow: more than one scene file given\n"); return EXIT_BAD_INPUT; }
    const char *scene_path = optind < argc ? argv[optind] : NULL;

    int avail = ms_method_available(opt.method);
    if (avail <= 0) {
        fprintf(stderr, "microshadow: --method: '%s' %s\n", opt.method,
                avail < 0 ? "is not compiled into this build" : "is not a known method (see --help)");
        return EXIT_BAD_INPUT;
    }
    char err[1024];
    /* Refuse unwritable outputs before a long render, and a visibility path of the wrong type. */
    if (out_vis) {
        size_t n = strlen(out_vis);
        if (n < 4 || (strcasecmp(out_vis + n - 4, ".pfm") && strcasecmp(out_vis + n - 4, ".exr"))) {
            fprintf(stderr, "microshadow: %s: the visibility image must end in .pfm or .exr\n", out_vis);
            return EXIT_BAD_INPUT;
        }
    }
    const char *outs[3] = { out_png, out_vis, out_stats };
    for (int i = 0; i < 3; i++)
        if (outs[i] && ms_check_writable(outs[i], err, sizeof err)) {
            fprintf(stderr, "microshadow: %s\n", err);
            return EXIT_BAD_INPUT;
        }

    ms_scene scene;
    if (scene_path) {
        if (ms_scene_load(scene_path, &scene, err, sizeof err)) {
            fprintf(stderr, "microshadow: %s\n", err);
            return EXIT_BAD_INPUT;
        }
    } else if (ms_scene_default(&scene)) {
        fprintf(stderr, "microshadow: out of memory building the default scene\n");
        return 1;
    }
    int last = -1;
    if (!quiet && isatty(STDERR_FILENO)) { opt.progress = progress_bar; opt.progress_user = &last; }
    ms_frame frame;
    if (ms_render(&scene, &opt, &frame, err, sizeof err)) {
        fprintf(stderr, "microshadow: %s: %s\n", scene_path ? scene_path : "built-in scene", err);
        ms_scene_free(&scene);
        return EXIT_BAD_INPUT;
    }
    int rc = write_outputs(&frame, out_png, out_vis, out_stats, err, sizeof err);
    if (rc) fprintf(stderr, "microshadow: %s\n", err);
    if (!quiet && rc == 0) {
        const ms_stats *s = &frame.stats;
        fprintf(stderr, "%s: %zu triangles, %dx%d, %d samples, method %s, %d threads: build %.3fs, setup %.3fs, primary %.3fs, "
                "shadow %.3fs (%.1f M shadow rays/s), total %.3fs -> %s\n",
                scene_path ? scene_path : "built-in scene", s->triangles, s->width, s->height, s->samples, s->method,
                s->threads, s->build_s, s->setup_s, s->primary_s, s->shadow_s,
                s->shadow_s > 0 ? (double)s->shadow_rays / s->shadow_s * 1e-6 : 0.0, s->total_s, out_png);
    }
    ms_frame_free(&frame);
    ms_scene_free(&scene);
    return rc;
}
