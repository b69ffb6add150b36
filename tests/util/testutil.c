#include "testutil.h"
#include "primary/primary.h"
#include "shadow/method.h"
#include "visibility/receiver.h"
#include <OpenEXR/openexr.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static void rm_tree(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    char p[4096];
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode)) { chmod(p, 0755); rm_tree(p); rmdir(p); }
        else unlink(p);
    }
    closedir(d);
}

const char *tu_tmpdir(const char *test_name)
{
    static char path[4096];
    mkdir(MS_TEST_TMPDIR, 0755);
    snprintf(path, sizeof path, "%s/%s", MS_TEST_TMPDIR, test_name);
    rm_tree(path);
    mkdir(path, 0755);
    return path;
}

const char *tu_path(char *buf, size_t n, const char *dir, const char *name)
{
    snprintf(buf, n, "%s/%s", dir, name);
    return buf;
}

int tu_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

void tu_write_texture_png(const char *path, int w, int h, const float *rgb)
{
    ms_frame f;
    memset(&f, 0, sizeof f);
    f.width = w;
    f.height = h;
    float *vis = calloc((size_t)w * h, sizeof *vis);
    assert_non_null(vis);
    f.vis = vis;
    f.rgb = (float *)rgb;
    f.exposure = 1.0f;
    char err[256];
    assert_int_equal(ms_write_png(&f, path, err, sizeof err), 0);
    free(vis);
}

void tu_unit3(double v[3])
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
}

int tu_file_exists(const char *path) { return access(path, F_OK) == 0; }

int tu_count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d))) n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    closedir(d);
    return n;
}

int tu_run_cli(const char *const *args, char *err_line, size_t n)
{
    /* a hang fails the test (after 600 s) instead of blocking ctest */
    const tu_run_opts opts = { .fsize_limit = 0, .umask = -1, .timeout_s = 600 };
    static char all[65536];
    const int rc = tu_run_cli_ex(args, &opts, all, sizeof all, NULL);
    if (err_line && n) {
        all[strcspn(all, "\n")] = 0;   /* the first line */
        snprintf(err_line, n, "%s", all);
    }
    return rc;
}

int tu_have_shared_scenes(void)
{
    struct stat st;
    if (stat(MS_SHARED_SCENES, &st) == 0 && S_ISDIR(st.st_mode)) return 1;
    fprintf(stderr, "skipping: shared scenes not found at %s\n", MS_SHARED_SCENES);
    return 0;
}

const char *tu_shared_scene(char *buf, size_t n, const char *rel)
{
    snprintf(buf, n, "%s/%s", MS_SHARED_SCENES, rel);
    return buf;
}

float *tu_read_pfm(const char *path, int *w, int *h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char magic[3] = { 0 };
    float scale;
    if (fscanf(f, "%2s %d %d %f", magic, w, h, &scale) != 4 || strcmp(magic, "Pf") || scale >= 0) { fclose(f); return NULL; }
    fgetc(f);
    size_t npx = (size_t)*w * *h;
    float *data = malloc(npx * sizeof(float));
    if (!data) { fclose(f); return NULL; }
    for (int y = *h - 1; y >= 0; y--)
        if (fread(data + (size_t)y * *w, sizeof(float), (size_t)*w, f) != (size_t)*w) { free(data); fclose(f); return NULL; }
    fclose(f);
    return data;
}

tu_agreement tu_compare_frames(const ms_frame *a, const ms_frame *b)
{
    tu_agreement g = { 0 };
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    for (long i = 0; i < (long)a->width * a->height; i++) {
        g.pixels++;
        const float x = a->vis[i], y = b->vis[i];
        if ((x < 0.0f) != (y < 0.0f)) { g.miss_mismatch++; g.differ++; continue; }
        if (x < 0.0f) continue;
        const double nf = a->front[i] > b->front[i] ? a->front[i] : b->front[i];
        const double steps = fabs((double)x - (double)y) * nf;
        const double ds = fabs((double)a->shadow[i] - (double)b->shadow[i]);
        if (steps > 1e-3) g.differ++;
        if (steps > 1.0 + 1e-3) g.beyond_one++;
        if (steps > g.max_steps) g.max_steps = steps;
        if (ds > g.max_ds) g.max_ds = ds;
        if (steps <= 1e-3 && ds > 1e-6) g.s_differ_same_v++;
        if (nf > 0 && ds > 8.0 * (steps + 1e-3) / nf) g.s_beyond++;
    }
    return g;
}

long tu_frame_values_differ(const ms_frame *a, const ms_frame *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    const int la = a->n_lights > 1 ? a->n_lights : 1, lb = b->n_lights > 1 ? b->n_lights : 1;
    assert_int_equal(la, lb);
    const long n = (long)a->width * a->height * la;
    long differ = 0;
    for (long i = 0; i < n; i++)
        differ += a->vis[i] != b->vis[i] || a->shadow[i] != b->shadow[i] || a->front[i] != b->front[i];
    return differ;
}

int tu_segment_hits(const float *t, const double p[3], const double L[3], double near, double far)
{
    double e1[3], e2[3], d[3], s[3], h[3], q[3];
    for (int c = 0; c < 3; c++) {
        e1[c] = (double)t[3 + c] - t[c];
        e2[c] = (double)t[6 + c] - t[c];
        d[c] = L[c] - p[c];
        s[c] = p[c] - t[c];
    }
    h[0] = d[1] * e2[2] - d[2] * e2[1]; h[1] = d[2] * e2[0] - d[0] * e2[2]; h[2] = d[0] * e2[1] - d[1] * e2[0];
    const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    if (fabs(det) < 1e-300) return 0;   /* parallel: a segment in the plane of a triangle never counts */
    const double f = 1.0 / det;
    const double b1 = f * (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]);
    q[0] = s[1] * e1[2] - s[2] * e1[1]; q[1] = s[2] * e1[0] - s[0] * e1[2]; q[2] = s[0] * e1[1] - s[1] * e1[0];
    const double b2 = f * (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]);
    const double u = f * (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]);
    const double m = fmin(fmin(b1, b2), 1.0 - b1 - b2);
    const double eps = 1e-6;
    if (m < -eps || u < near - eps || u > far + eps) return 0;
    if (m < eps || fabs(u - near) < eps || fabs(u - far) < eps) return 2;
    return 1;
}

void tu_query_from_hit(ms_shadow_query *q, const ms_hit *h, int x, int y)
{
    ms_query_from_hit(q, h, (uint32_t)x, (uint32_t)y);
}

void tu_ctx_init(ms_render_ctx *ctx, const ms_scene *sc, const ms_bvh *bvh, int W, int H, int k)
{
    ms_render_ctx_init(ctx, sc, bvh, &sc->light, MS_PATTERN_GRID, k, 0, 1);
    assert_int_equal(ms_camera_basis_init(&ctx->cam, &sc->camera, W, H), 0);
    ctx->isa_cap = tu_isa_cap();
}

void tu_ctx_set_pattern(ms_render_ctx *ctx, ms_pattern p)
{
    ctx->pattern = p;
    ctx->samples = ms_pattern_spp(p, ctx->k);
    ctx->mask_words = (ctx->samples + 63) / 64;
}

int tu_shadow_vs(const ms_shadow_method *m, void *state, const ms_render_ctx *ctx, const ms_shadow_query *q, int n,
                 float *v, float *s, uint64_t *counters)
{
    const size_t mw = (size_t)ctx->mask_words;
    uint64_t *front = calloc((size_t)n * mw + 1, sizeof *front), *vis = calloc((size_t)n * mw + 1, sizeof *vis);
    float *pts = ctx->pattern == MS_PATTERN_GRID ? NULL : malloc((size_t)ctx->samples * 3 * sizeof *pts);
    assert_non_null(front);
    assert_non_null(vis);
    for (int i = 0; i < n; i++) {
        if (pts) ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q[i].px, q[i].py, ctx->seed, pts);
        ms_front_mask(ctx, &q[i], pts, front + i * mw);
    }
    int rc = m->visibility(state, ctx, q, n, front, vis, counters);
    for (int i = 0; i < n && rc == 0; i++) {
        if (pts) ms_pattern_points(ctx->pattern, &ctx->light, ctx->k, q[i].px, q[i].py, ctx->seed, pts);
        ms_resolve_vs(ctx, &q[i], pts, front + i * mw, vis + i * mw, &v[i], &s[i]);
    }
    free(front);
    free(vis);
    free(pts);
    return rc;
}

ms_isa tu_isa_cap(void)
{
    const char *e = getenv("MS_TEST_ISA");
    ms_isa cap = MS_ISA_AUTO;
    if (e && *e && ms_isa_from_name(e, &cap) != 0) {
        fprintf(stderr, "MS_TEST_ISA=%s: expected auto, scalar, avx2 or avx512\n", e);
        abort();
    }
    return cap;
}

void tu_bake_options(ms_bake_options *bo, int size, int uv_set, int samples)
{
    memset(bo, 0, sizeof *bo);
    bo->size = size;
    bo->uv_set = uv_set;
    bo->points.samples = samples;
    bo->points.isa = tu_isa_cap();
}

void tu_load_scene_text(const char *dir, const char *text, ms_scene *sc)
{
    char json[4096], err[512] = "";
    assert_int_equal(tu_write_file(tu_path(json, sizeof json, dir, "scene.json"), text), 0);
    if (ms_scene_load(json, sc, err, sizeof err) != MS_OK) fail_msg("%s: %s", json, err);
}

void tu_tri_point(const ms_scene *sc, const float *uvs, size_t t, const double w[3], float p[3], double uv[2])
{
    p[0] = p[1] = p[2] = 0.0f;
    uv[0] = uv[1] = 0.0;
    for (int c = 0; c < 3; c++) {
        for (int d = 0; d < 3; d++) p[d] += (float)(w[c] * sc->tri[9 * t + 3 * (size_t)c + d]);
        for (int d = 0; d < 2; d++) uv[d] += w[c] * uvs[6 * t + 2 * (size_t)c + d];
    }
}

double tu_lightmap_green(const ms_frame *f, int page, double u, double v)
{
    const int S = f->width;
    const double x = u * S - 0.5, y = v * S - 0.5;
    const int x0 = (int)floor(x), y0 = (int)floor(y);
    const double fx = x - x0, fy = y - y0;
    double s = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const int xx = x0 + i < 0 ? 0 : x0 + i >= S ? S - 1 : x0 + i;
            const int yy = y0 + j < 0 ? 0 : y0 + j >= S ? S - 1 : y0 + j;
            s += (i ? fx : 1 - fx) * (j ? fy : 1 - fy) * f->rgb[3 * ((size_t)(page * S + yy) * S + xx) + 1];
        }
    return s;
}

double tu_point_irradiance(const ms_accel *acc, const ms_scene *sc, const float p[3], const float n[3], uint32_t tri,
                           const double uv[2], int size)
{
    const uint32_t key[2] = { (uint32_t)(uv[0] * size), (uint32_t)(uv[1] * size) };
    ms_points pts = { 1, p, n, &tri, key };
    ms_points_options po;
    memset(&po, 0, sizeof po);
    po.samples = 256;
    po.isa = tu_isa_cap();
    float S;
    char err[512] = "";
    assert_int_equal(ms_visibility_points(acc, NULL, &pts, &po, NULL, &S, NULL, NULL, err, sizeof err), MS_OK);
    return ms_light_irradiance(&sc->light, p, n) * S * sc->light.emission.y;
}

void tu_render_options_default(ms_render_options *o)
{
    ms_render_options_default(o);
    o->isa = tu_isa_cap();
}

int tu_isa_allowed(ms_isa isa)
{
    const ms_isa cap = tu_isa_cap();
    return cap == MS_ISA_AUTO || isa <= cap;
}

int tu_run_cli_ex(const char *const *args, const tu_run_opts *opts, char *err_all, size_t n, tu_run_result *res)
{
    char errpath[4096];
    snprintf(errpath, sizeof errpath, "%s/cli-stderr-ex-%d.txt", MS_TEST_TMPDIR, (int)getpid());
    mkdir(MS_TEST_TMPDIR, 0755);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int nul = open("/dev/null", O_WRONLY);
        if (fd >= 0) dup2(fd, 2);
        if (nul >= 0) dup2(nul, 1);
        if (opts && opts->fsize_limit > 0) {
            signal(SIGXFSZ, SIG_IGN);
            struct rlimit rl = { (rlim_t)opts->fsize_limit, (rlim_t)opts->fsize_limit };
            setrlimit(RLIMIT_FSIZE, &rl);
        }
        if (opts && opts->umask >= 0) umask((mode_t)opts->umask);
        alarm(opts && opts->timeout_s > 0 ? (unsigned)opts->timeout_s : 120);
        const char *argv[64];
        int a = 0;
        argv[a++] = MS_CLI_PATH;
        for (int i = 0; args[i] && a < 63; i++) argv[a++] = args[i];
        argv[a] = NULL;
        execv(MS_CLI_PATH, (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    wait4(pid, &status, 0, &ru);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (res) {
        res->max_rss_mb = (double)ru.ru_maxrss / 1024.0;
        res->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        res->lines = 0;
    }
    if (err_all && n) {
        err_all[0] = 0;
        FILE *f = fopen(errpath, "rb");
        if (f) {
            size_t k = fread(err_all, 1, n - 1, f);
            err_all[k] = 0;
            fclose(f);
        }
        if (res)
            for (const char *p = err_all; *p; p++) res->lines += *p == '\n';
    }
    unlink(errpath);
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

void tu_make_quad(ms_scene *sc)
{
    static const float tri[4][9] = {
        { -10, 0, -10, 10, 0, 10, 10, 0, -10 }, { -10, 0, -10, -10, 0, 10, 10, 0, 10 },
        { -2, 2, -2, 2, 2, 2, 2, 2, -2 }, { -2, 2, -2, -2, 2, 2, 2, 2, 2 } };
    memset(sc, 0, sizeof *sc);
    sc->tri = malloc(sizeof tri);
    assert_non_null(sc->tri);
    memcpy(sc->tri, tri, sizeof tri);
    sc->n_tris = 4;
    sc->camera = (ms_camera){ { 0, 10, 12 }, { 0, 0, 0 }, { 0, 1, 0 }, 60.0f, 96, 96, MS_CAMERA_PINHOLE, 0, 0 };
    sc->light = (ms_light){ { -1, 6, -1 }, { 2, 0, 0 }, { 0, 0, 2 }, { 1, 1, 1 }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    sc->samples = 1024;
}

/* float -> half for the values tests use (normal halves, zero): exact or -1. */
static int to_half(float f, uint16_t *out)
{
    if (f == 0.0f) { *out = signbit(f) ? 0x8000 : 0; return 0; }
    uint32_t u;
    memcpy(&u, &f, 4);
    const uint32_t sign = u >> 31, mant = u & 0x7fffff;
    const int e = (int)((u >> 23) & 0xff) - 127;
    if (e < -14 || e > 15 || (mant & 0x1fff)) return -1;   /* not a normal half, or inexact */
    *out = (uint16_t)(sign << 15 | (uint32_t)(e + 15) << 10 | mant >> 13);
    return 0;
}

int tu_write_exr(const char *path, int w, int h, int nch, const char *const *names, const float *const *plane, int half,
                 int compression)
{
    uint16_t *hp[16] = { 0 };
    if (nch < 1 || nch > 16) return -1;
    int rc = -1;
    for (int c = 0; c < nch && half; c++) {
        hp[c] = malloc((size_t)w * h * sizeof *hp[c]);
        if (!hp[c]) goto out;
        for (size_t i = 0; i < (size_t)w * h; i++)
            if (to_half(plane[c][i], &hp[c][i])) goto out;
    }
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_result_t r = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    int part = 0, lines = 1, enc_init = 0;
    exr_encode_pipeline_t enc;
    if (r == EXR_ERR_SUCCESS) r = exr_add_part(ctx, "tex", EXR_STORAGE_SCANLINE, &part);
    if (r == EXR_ERR_SUCCESS) r = exr_initialize_required_attr_simple(ctx, part, w, h, (exr_compression_t)compression);
    /* OpenEXR keeps channels sorted by name: add them in that order */
    int order[16];
    for (int c = 0; c < nch; c++) order[c] = c;
    for (int a = 1; a < nch; a++)
        for (int b = a; b > 0 && strcmp(names[order[b - 1]], names[order[b]]) > 0; b--) { int t = order[b]; order[b] = order[b - 1]; order[b - 1] = t; }
    for (int c = 0; c < nch && r == EXR_ERR_SUCCESS; c++)
        r = exr_add_channel(ctx, part, names[order[c]], half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (r == EXR_ERR_SUCCESS) r = exr_write_header(ctx);
    if (r == EXR_ERR_SUCCESS) r = exr_get_scanlines_per_chunk(ctx, part, &lines);
    for (int y = 0; r == EXR_ERR_SUCCESS && y < h; y += lines) {
        exr_chunk_info_t ci;
        r = exr_write_scanline_chunk_info(ctx, part, y, &ci);
        if (r == EXR_ERR_SUCCESS) r = enc_init ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (r != EXR_ERR_SUCCESS) break;
        for (int c = 0; c < nch; c++) {
            const int src = order[c];
            const size_t esz = half ? 2 : 4;
            enc.channels[c].encode_from_ptr = half ? (const uint8_t *)(hp[src] + (size_t)y * w) : (const uint8_t *)(plane[src] + (size_t)y * w);
            enc.channels[c].user_pixel_stride = (int32_t)esz;
            enc.channels[c].user_line_stride = (int32_t)(esz * (size_t)w);
            enc.channels[c].user_bytes_per_element = (int16_t)esz;
            enc.channels[c].user_data_type = (uint16_t)(half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT);
        }
        if (!enc_init) { r = exr_encoding_choose_default_routines(ctx, part, &enc); enc_init = 1; }
        if (r == EXR_ERR_SUCCESS) r = exr_encoding_run(ctx, part, &enc);
    }
    if (enc_init) exr_encoding_destroy(ctx, &enc);
    const exr_result_t fin = ctx ? exr_finish(&ctx) : EXR_ERR_SUCCESS;
    rc = r == EXR_ERR_SUCCESS && fin == EXR_ERR_SUCCESS ? 0 : -1;
out:
    for (int c = 0; c < 16; c++) free(hp[c]);
    return rc;
}

/* Reads channel `name` of a one-part EXR (w x h) as floats into img; -1 if absent. */
int tu_read_exr_channel(const char *path, const char *name, int w, int h, float *img)
{
    exr_context_t ctx = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_read(&ctx, path, &init), EXR_ERR_SUCCESS);
    const exr_attr_chlist_t *chl = NULL;
    assert_int_equal(exr_get_channels(ctx, 0, &chl), EXR_ERR_SUCCESS);
    int want = -1;
    for (int c = 0; c < chl->num_channels; c++)
        if (!strcmp(chl->entries[c].name.str, name)) want = c;
    if (want < 0) { exr_finish(&ctx); return -1; }
    exr_attr_box2i_t dw;
    assert_int_equal(exr_get_data_window(ctx, 0, &dw), EXR_ERR_SUCCESS);
    assert_int_equal(dw.max.x - dw.min.x + 1, w);
    assert_int_equal(dw.max.y - dw.min.y + 1, h);
    int lines = 0;
    assert_int_equal(exr_get_scanlines_per_chunk(ctx, 0, &lines), EXR_ERR_SUCCESS);
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int dec_init = 0;
    for (int y = dw.min.y; y <= dw.max.y; y += lines) {
        exr_chunk_info_t ci;
        assert_int_equal(exr_read_scanline_chunk_info(ctx, 0, y, &ci), EXR_ERR_SUCCESS);
        if (!dec_init) assert_int_equal(exr_decoding_initialize(ctx, 0, &ci, &dec), EXR_ERR_SUCCESS);
        else assert_int_equal(exr_decoding_update(ctx, 0, &ci, &dec), EXR_ERR_SUCCESS);
        for (int c = 0; c < dec.channel_count; c++) dec.channels[c].decode_to_ptr = NULL;
        dec.channels[want].decode_to_ptr = (uint8_t *)(img + (size_t)(ci.start_y - dw.min.y) * w);
        dec.channels[want].user_pixel_stride = sizeof(float);
        dec.channels[want].user_line_stride = (int32_t)sizeof(float) * w;
        dec.channels[want].user_bytes_per_element = sizeof(float);
        dec.channels[want].user_data_type = EXR_PIXEL_FLOAT;
        if (!dec_init) { assert_int_equal(exr_decoding_choose_default_routines(ctx, 0, &dec), EXR_ERR_SUCCESS); dec_init = 1; }
        assert_int_equal(exr_decoding_run(ctx, 0, &dec), EXR_ERR_SUCCESS);
    }
    exr_decoding_destroy(ctx, &dec);
    exr_finish(&ctx);
    return 0;
}

void tu_render_ok(const ms_scene *sc, const ms_render_options *o, ms_frame *f)
{
    char err[512] = "";
    if (ms_render(sc, o, f, err, sizeof err)) fail_msg("ms_render(%s): %s", o->method ? o->method : MS_DEFAULT_METHOD, err);
}

void tu_every_method_as_raytrace(const ms_scene *sc, ms_render_options *o, const char *what, ms_frame *ref,
                                 tu_method_check check, void *user)
{
    o->method = "raytrace";
    tu_render_ok(sc, o, ref);
    for (const char *const *m = ms_method_names(); *m; m++) {
        ms_frame f;
        o->method = *m;
        tu_render_ok(sc, o, &f);
        const long differ = tu_frame_values_differ(&f, ref);
        if (differ) fail_msg("%s, method %s: %ld values differ from raytrace", what, *m, differ);
        if (check) check(*m, &f, ref, user);
        ms_frame_free(&f);
    }
}

float *tu_render_vis(const ms_scene *sc, const ms_render_options *o, ms_stats *stats)
{
    ms_frame f;
    tu_render_ok(sc, o, &f);
    const size_t n = (size_t)f.width * f.height;
    float *v = malloc(n * sizeof *v);
    assert_non_null(v);
    memcpy(v, f.vis, n * sizeof *v);
    if (stats) *stats = f.stats;
    ms_frame_free(&f);
    return v;
}

void tu_unit_icosphere(int levels, double **verts, size_t *n_verts, int **tris, size_t *n_tris)
{
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    const double iv[12][3] = { { -1, t, 0 }, { 1, t, 0 }, { -1, -t, 0 }, { 1, -t, 0 }, { 0, -1, t }, { 0, 1, t },
                               { 0, -1, -t }, { 0, 1, -t }, { t, 0, -1 }, { t, 0, 1 }, { -t, 0, -1 }, { -t, 0, 1 } };
    const int it[20][3] = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 }, { 1, 5, 9 }, { 5, 11, 4 },
                            { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 }, { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 },
                            { 3, 8, 9 }, { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
    size_t nt = 20, np = 12;
    const size_t maxt = 20 * ((size_t)1 << (2 * levels)), maxp = 12 + 30 * ((size_t)1 << (2 * levels));
    double *p = malloc(sizeof(double) * 3 * maxp);
    int *tri = malloc(sizeof(int) * 3 * maxt), *nt2 = malloc(sizeof(int) * 3 * maxt);
    assert_true(p && tri && nt2);
    for (int i = 0; i < 12; i++) {
        const double l = sqrt(iv[i][0] * iv[i][0] + iv[i][1] * iv[i][1] + iv[i][2] * iv[i][2]);
        for (int a = 0; a < 3; a++) p[3 * i + a] = iv[i][a] / l;
    }
    memcpy(tri, it, sizeof it);
    for (int lv = 0; lv < levels; lv++) {
        /* midpoint cache: a small open-addressing table keyed by the vertex pair */
        const size_t hcap = 8 * nt * 3;
        uint64_t *key = calloc(hcap, sizeof *key);
        int *val = malloc(sizeof(int) * hcap);
        assert_true(key && val);
        for (size_t k = 0; k < nt; k++) {
            const int v[3] = { tri[3 * k], tri[3 * k + 1], tri[3 * k + 2] };
            int mid[3];
            for (int e = 0; e < 3; e++) {
                const int a = v[e], b = v[(e + 1) % 3];
                const uint64_t kk = (a < b ? ((uint64_t)a << 32 | (uint64_t)b) : ((uint64_t)b << 32 | (uint64_t)a)) + 1;
                size_t h = (size_t)(kk * 0x9E3779B97F4A7C15ull % hcap);
                while (key[h] && key[h] != kk) h = (h + 1) % hcap;
                if (!key[h]) {
                    key[h] = kk;
                    double q[3], l = 0;
                    for (int x = 0; x < 3; x++) { q[x] = 0.5 * (p[3 * a + x] + p[3 * b + x]); l += q[x] * q[x]; }
                    for (int x = 0; x < 3; x++) p[3 * np + x] = q[x] / sqrt(l);
                    val[h] = (int)np++;
                }
                mid[e] = val[h];
            }
            const int nn[4][3] = { { v[0], mid[0], mid[2] }, { v[1], mid[1], mid[0] }, { v[2], mid[2], mid[1] }, { mid[0], mid[1], mid[2] } };
            memcpy(nt2 + 12 * k, nn, sizeof nn);
        }
        memcpy(tri, nt2, sizeof(int) * 12 * nt);
        nt *= 4;
        free(key);
        free(val);
    }
    free(nt2);
    *verts = p;
    *n_verts = np;
    *tris = tri;
    *n_tris = nt;
}

void tu_png_base64(const unsigned char *rgb, int w, int h, char *out, size_t cap)
{
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    im.width = (png_uint_32)w;
    im.height = (png_uint_32)h;
    im.format = PNG_FORMAT_RGB;
    png_alloc_size_t len = 0;
    assert_true(png_image_write_to_memory(&im, NULL, &len, 0, rgb, 0, NULL));   /* the size it needs */
    unsigned char *mem = malloc(len);
    assert_non_null(mem);
    assert_true(png_image_write_to_memory(&im, mem, &len, 0, rgb, 0, NULL));
    assert_true(4 * ((len + 2) / 3) + 1 <= cap);
    tu_base64(mem, len, out);
    free(mem);
}

void tu_base64(const unsigned char *in, size_t n, char *out)
{
    static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        const uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = tab[v >> 18 & 63];
        out[o++] = tab[v >> 12 & 63];
        out[o++] = i + 1 < n ? tab[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? tab[v & 63] : '=';
    }
    out[o] = 0;
}

uint64_t tu_stat_counter(const ms_stats *st, const char *name)
{
    uint64_t v = 0;
    if (!ms_stats_counter(st, name, &v)) fail_msg("no counter %s", name);
    return v;
}

struct ms_shadow_query *tu_frame_queries(const struct ms_render_ctx *ctx, int size, int *nq)
{
    const ms_primary_method *pm = ms_find_primary_method("bvh");
    assert_non_null(pm);
    char err[256];
    void *ps = NULL;
    assert_int_equal(pm->create(ctx, &ps, err, sizeof err), 0);
    ms_hit *hits = malloc((size_t)size * size * sizeof *hits);
    ms_shadow_query *q = malloc((size_t)size * size * sizeof *q);
    assert_non_null(hits);
    assert_non_null(q);
    pm->trace(ps, ctx, 0, 0, size, size, hits);
    pm->destroy(ps);
    int n = 0;
    for (int i = 0; i < size * size; i++)
        if (hits[i].prim != UINT32_MAX) tu_query_from_hit(&q[n++], &hits[i], i % size, i / size);
    free(hits);
    *nq = n;
    return q;
}

void tu_shared_scene_load(const char *rel, ms_scene *sc)
{
    if (!tu_have_shared_scenes()) skip();
    char path[4096], err[512] = "";
    const int rc = ms_scene_load(tu_shared_scene(path, sizeof path, rel), sc, err, sizeof err);
    if (rc) fail_msg("%s: %s", rel, err);
}

/* 1 if name is one of the comma-separated names of list. */
static int in_list(const char *list, const char *name)
{
    const size_t len = strlen(name);
    for (const char *p = list; *p;) {
        const size_t k = strcspn(p, ",");
        if (k == len && !strncmp(p, name, len)) return 1;
        p += k + (p[k] == ',');
    }
    return 0;
}

int tu_run_tests(const char *group, const struct CMUnitTest *tests, size_t n, CMFixtureFunction setup,
                 CMFixtureFunction teardown, int argc, char **argv)
{
    if (argc == 1) return _cmocka_run_group_tests(group, tests, n, setup, teardown);
    const int only = argc == 3 && !strcmp(argv[1], "--only"), except = argc == 3 && !strcmp(argv[1], "--except");
    if (!only && !except) {
        fprintf(stderr, "%s: usage: %s [--only|--except NAME[,NAME...]]\n", argv[0], argv[0]);
        return 1;
    }
    /* every name given is a test here */
    for (const char *p = argv[2]; *p;) {
        const size_t k = strcspn(p, ",");
        size_t i = 0;
        while (i < n && !(strlen(tests[i].name) == k && !strncmp(tests[i].name, p, k))) i++;
        if (i == n) {
            fprintf(stderr, "%s: no test named \"%.*s\"\n", argv[0], (int)k, p);
            return 1;
        }
        p += k + (p[k] == ',');
    }
    struct CMUnitTest *part = malloc((n ? n : 1) * sizeof *part);
    if (!part) return 1;
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (in_list(argv[2], tests[i].name) == only) part[m++] = tests[i];
    if (m == 0) {
        fprintf(stderr, "%s: %s %s selects no test\n", argv[0], argv[1], argv[2]);
        free(part);
        return 1;
    }
    const int rc = _cmocka_run_group_tests(group, part, m, setup, teardown);
    free(part);
    return rc;
}
