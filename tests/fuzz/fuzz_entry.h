/* The fuzz targets' bodies, shared by the libFuzzer harnesses (fuzz_*.c, clang only) and by the ctest
 * program test_fuzz_inputs, which replays every committed seed and kept crash input with any compiler.
 * Each body checks the loaders' contract: no crash (the sanitizers), and on failure exactly one line of
 * message naming the file. */
#ifndef MS_FUZZ_ENTRY_H
#define MS_FUZZ_ENTRY_H
#include "microshadow.h"
#include "scene/scene_internal.h"
#include "image/exr_read.h"
#include "image/png_read.h"
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MS_FUZZ_MESH_PATH "/nonexistent-microshadow-fuzz/input."

/* One line, "FILE: problem"; name, when given, must be the file. */
static inline void ms_fuzz_check_message(const char *err, const char *name)
{
    const char *colon = strstr(err, ": ");
    if (!colon || colon == err || strchr(err, '\n') || (name && strncmp(err, name, strlen(name)))) {
        fprintf(stderr, "bad error message: '%s' (must be one line 'FILE: problem'%s%s)\n", err, name ? " naming " : "",
                name ? name : "");
        abort();
    }
}

/* One mesh file of format ext (obj, ply, off, stl, gltf), from bytes; 0 if it loaded. */
static inline int ms_fuzz_mesh(const char *ext, const uint8_t *data, size_t size)
{
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    memcpy(buf, data, size);
    buf[size] = 0;
    char path[320], err[1024] = "";
    snprintf(path, sizeof path, "%s%s", MS_FUZZ_MESH_PATH, ext);
    ms_tri_soup soup = { 0 };
    int rc = ms_mesh_load_memory(buf, size, ext, path, &soup, err, sizeof err);
    if (rc) ms_fuzz_check_message(err, path);
    else if (soup.n == 0) abort();   /* success means triangles */
    ms_soup_free(&soup);
    free(buf);
    return rc;
}

/* A light's emission texture as an EXR file, from bytes (the decoder the scene loader calls for one);
 * 0 if it decoded. Success means texels within the size limit, each in [0, MS_MAX_LIGHT_TEXEL]. */
static inline int ms_fuzz_exr(const uint8_t *data, size_t size)
{
    const char *path = MS_FUZZ_MESH_PATH "exr";
    float *rgb = NULL;
    int w = 0, h = 0;
    char err[1024] = "";
    int rc = ms_exr_decode_linear(path, data, size, MS_MAX_LIGHT_TEXTURE, &rgb, &w, &h, err, sizeof err);
    if (rc) ms_fuzz_check_message(err, path);
    else {
        if (w < 1 || h < 1 || w > MS_MAX_LIGHT_TEXTURE || h > MS_MAX_LIGHT_TEXTURE) abort();
        for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++)
            if (!(rgb[i] >= 0.0f) || !(rgb[i] <= MS_MAX_LIGHT_TEXEL)) abort();
    }
    free(rgb);
    return rc;
}

/* A material texture (src/scene/texture.c: JPEG through TurboJPEG, and PNG and KTX2, told apart by content),
 * from bytes; 0 if it decoded. Success means an image within the size limit with its pixels. The decoded
 * budget is 16 MiB (2048x2048), not the scene's 1 GiB: a header can declare 16384x16384 in a few hundred
 * bytes, and decoding that (libjpeg fills a truncated file's missing rows) costs seconds per input (a
 * 1031x8197 one from 331 bytes once passed the 10 s timeout under ASan on a loaded machine,
 * crashes/jpeg/); the size checks are the same code either way. */
static inline int ms_fuzz_jpeg(const uint8_t *data, size_t size)
{
    const char *path = MS_FUZZ_MESH_PATH "jpg";
    ms_texture t;
    char err[1024] = "";
    int rc = ms_texture_decode(data, size, path, 0, (size_t)16 << 20, &t, err, sizeof err);
    if (rc) ms_fuzz_check_message(err, path);
    else if (!t.rgba || t.width < 1 || t.height < 1 || (size_t)t.width * (size_t)t.height * 4 > ((size_t)16 << 20)) abort();
    else {
        volatile uint8_t sink = 0;
        for (size_t i = 0; i < (size_t)t.width * (size_t)t.height * 4; i += 4093) sink ^= t.rgba[i];
        (void)sink;
    }
    free(t.rgba);
    return rc;
}

/* A material texture decoded from bytes by content (src/scene/texture.c), named path in messages; 0 if it
 * decoded. Decoded twice, rows top-down and bottom-up: success means both decode, each within the size limit
 * and the 16 MiB budget of ms_fuzz_jpeg, the same image with its rows reversed. */
static inline int ms_fuzz_texture_both_ways(const char *path, const uint8_t *data, size_t size)
{
    const size_t budget = (size_t)16 << 20;
    ms_texture t[2];
    char err[1024] = "";
    int rc = 0;
    for (int flip = 0; flip < 2; flip++) {
        err[0] = 0;
        const int r = ms_texture_decode(data, size, path, flip, budget, &t[flip], err, sizeof err);
        if (r) ms_fuzz_check_message(err, path);
        else if (!t[flip].rgba || t[flip].width < 1 || t[flip].height < 1 ||
                 (size_t)t[flip].width * (size_t)t[flip].height * 4 > budget)
            abort();
        if (flip && r != rc) abort();   /* the rows' order cannot decide whether a file decodes */
        rc = r;
    }
    if (!rc) {
        const size_t row = (size_t)t[0].width * 4, h = (size_t)t[0].height;
        if (t[1].width != t[0].width || t[1].height != t[0].height) abort();
        for (size_t y = 0; y < h; y++)
            if (memcmp(t[0].rgba + y * row, t[1].rgba + (h - 1 - y) * row, row)) abort();
    }
    free(t[0].rgba);
    free(t[1].rgba);
    return rc;
}

/* A KTX2 texture (src/scene/texture_ktx2.c: the container, uncompressed and Zstandard levels). */
static inline int ms_fuzz_ktx2(const uint8_t *data, size_t size)
{
    return ms_fuzz_texture_both_ways(MS_FUZZ_MESH_PATH "ktx2", data, size);
}

/* A WebP texture (src/scene/texture.c through libwebp: lossy, lossless, alpha; animated files refused). */
static inline int ms_fuzz_webp(const uint8_t *data, size_t size)
{
    return ms_fuzz_texture_both_ways(MS_FUZZ_MESH_PATH "webp", data, size);
}

static inline void ms_fuzz_ignore_warning(void *user, const char *msg) { (void)user; (void)msg; }

/* A PNG texture, from bytes, through both decoders: a light's emission texture (src/image/png_read.c, linear
 * floats) and a material's base-colour texture (src/scene/texture.c, RGBA8); 0 if both decoded. Success means
 * the size within the limits and, for the light, texels in [0, 1]. */
static inline int ms_fuzz_png(const uint8_t *data, size_t size)
{
    const char *path = MS_FUZZ_MESH_PATH "png";
    float *rgb = NULL;
    int w = 0, h = 0;
    char err[1024] = "";
    int rc = ms_png_decode_linear(path, data, size, MS_MAX_LIGHT_TEXTURE, &rgb, &w, &h, err, sizeof err);
    if (rc) ms_fuzz_check_message(err, path);
    else {
        if (w < 1 || h < 1 || w > MS_MAX_LIGHT_TEXTURE || h > MS_MAX_LIGHT_TEXTURE) abort();
        for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++)
            if (!(rgb[i] >= 0.0f && rgb[i] <= 1.0f)) abort();
    }
    free(rgb);
    ms_tri_soup soup = { 0 };
    err[0] = 0;
    const long t = ms_soup_add_texture_memory(&soup, data, size, path, (int)(size & 1), err, sizeof err);
    if (t < 0) ms_fuzz_check_message(err, path);
    else if (t != 0 || soup.n_tex != 1 || soup.tex[0].width < 1 || soup.tex[0].height < 1 ||
             soup.tex[0].width > MS_MAX_TEXTURE_SIDE || soup.tex[0].height > MS_MAX_TEXTURE_SIDE)
        abort();
    ms_soup_free(&soup);
    return rc || t < 0;
}

/* An MTL file, from bytes (mtl.c, as an OBJ's mtllib reads it; its maps name files that do not exist, or
 * absolute paths and paths leading out, which are refused); 0 if it loaded. Success means every material's
 * factors in [0, 1] and its texture indices valid or -1. */
static inline int ms_fuzz_mtl(const uint8_t *data, size_t size)
{
    const char *path = MS_FUZZ_MESH_PATH "mtl";
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    memcpy(buf, data, size);
    buf[size] = 0;
    ms_tri_soup soup = { 0 };
    ms_mtl_lib lib;
    memset(&lib, 0, sizeof lib);
    char err[1024] = "";
    ms_material_warnings_begin();   /* the maps that cannot be read: counted, then dropped */
    int rc = ms_mtl_load_memory(buf, size, path, &soup, &lib, err, sizeof err);
    ms_material_warnings_end(0);
    if (rc) ms_fuzz_check_message(err, path);
    else {
        if (lib.n != soup.n_mats) abort();
        for (size_t i = 0; i < soup.n_mats; i++) {
            const ms_material *m = &soup.mats[i];
            for (int c = 0; c < 4; c++)
                if (!(m->base_color[c] >= 0.0f && m->base_color[c] <= 1.0f)) abort();
            if (!(m->metallic >= 0.0f && m->metallic <= 1.0f) || !(m->roughness >= 0.0f && m->roughness <= 1.0f)) abort();
            if (m->base_color_texture >= (int32_t)soup.n_tex || m->alpha_texture >= (int32_t)soup.n_tex) abort();
        }
    }
    ms_mtl_lib_free(&lib);
    ms_soup_free(&soup);
    free(buf);
    return rc;
}

/* A scene file, from bytes, beside a directory holding one small valid mesh (a.obj); 0 if it loaded. */
static inline int ms_fuzz_scene(const char *dir, const uint8_t *data, size_t size)
{
    ms_set_warning_handler(ms_fuzz_ignore_warning, NULL);
    char *buf = malloc(size + 1);
    if (!buf) return 0;
    memcpy(buf, data, size);
    buf[size] = 0;
    char path[4096], err[1024] = "";
    snprintf(path, sizeof path, "%s/scene.json", dir);
    ms_scene s;
    int rc = ms_scene_parse(buf, size, path, &s, err, sizeof err);
    if (rc) ms_fuzz_check_message(err, NULL);   /* the scene file or a mesh file it names */
    else ms_scene_free(&s);
    free(buf);
    return rc;
}

static char ms_fuzz_dir[64];

static inline void ms_fuzz_remove_dir(void)
{
    char p[128];
    snprintf(p, sizeof p, "%s/a.obj", ms_fuzz_dir);
    unlink(p);
    rmdir(ms_fuzz_dir);
}

/* The directory for ms_fuzz_scene, created once and removed at exit. */
static inline const char *ms_fuzz_scene_dir(void)
{
    char *dir = ms_fuzz_dir;
    if (dir[0]) return dir;
    snprintf(dir, sizeof ms_fuzz_dir, "/tmp/microshadow-fuzz-XXXXXX");
    if (!mkdtemp(dir)) abort();
    atexit(ms_fuzz_remove_dir);
    char p[128];
    snprintf(p, sizeof p, "%s/a.obj", dir);
    FILE *f = fopen(p, "wb");
    if (!f) abort();
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n", f);
    fclose(f);
    return dir;
}

#endif
