/* Mesh files: chosen by extension (no probing), read by microshadow's own readers (OBJ, PLY, OFF, STL:
 * mesh_reader.h) or cgltf (glTF), then checked for finite coordinates. */
#include "scene_internal.h"
#include "mesh_reader.h"
#include "microshadow.h"
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ms_soup_push_uv(ms_tri_soup *soup, const float v[9], const float *const uv[MS_SOUP_UV_SETS])
{
    return ms_soup_push_full(soup, v, uv, MS_NO_MATERIAL, NULL);
}

int ms_soup_push_full(ms_tri_soup *soup, const float v[9], const float *const uv[MS_SOUP_UV_SETS],
                      uint32_t material, const float *normal9)
{
    return ms_soup_push_d(soup, v, NULL, uv, material, normal9);
}

int ms_soup_push_d(ms_tri_soup *soup, const float v[9], const double *vd, const float *const uv[MS_SOUP_UV_SETS],
                   uint32_t material, const float *normal9)
{
    if (soup->n == soup->cap) {
        size_t cap = soup->cap ? 2 * soup->cap : 1024;
        float *t = realloc(soup->tri, cap * 9 * sizeof(float));
        if (!t) return -1;
        soup->tri = t;
        double *td = realloc(soup->tri_d, cap * 9 * sizeof(double));
        if (!td) return -1;
        soup->tri_d = td;
        uint32_t *m = realloc(soup->mesh, cap * sizeof *m);
        if (!m) return -1;
        soup->mesh = m;
        for (int s = 0; s < MS_SOUP_UV_SETS; s++) {
            if (!soup->uv[s]) continue;
            float *u = realloc(soup->uv[s], cap * 6 * sizeof(float));
            if (!u) return -1;
            soup->uv[s] = u;
        }
        if (soup->material) {
            uint32_t *mt = realloc(soup->material, cap * sizeof *mt);
            if (!mt) return -1;
            soup->material = mt;
        }
        if (soup->normal) {
            float *nn = realloc(soup->normal, cap * 9 * sizeof(float));
            if (!nn) return -1;
            soup->normal = nn;
        }
        soup->cap = cap;
    }
    if (material != MS_NO_MATERIAL && !soup->material) {   /* the first triangle with a material */
        soup->material = malloc(soup->cap * sizeof *soup->material);
        if (!soup->material) return -1;
        for (size_t i = 0; i < soup->n; i++) soup->material[i] = MS_NO_MATERIAL;
    }
    if (soup->material) soup->material[soup->n] = material;
    if (normal9 && !soup->normal) {
        soup->normal = malloc(soup->cap * 9 * sizeof(float));
        if (!soup->normal) return -1;
        for (size_t i = 0; i < 9 * soup->n; i++) soup->normal[i] = NAN;
    }
    if (soup->normal) {
        if (normal9) memcpy(soup->normal + 9 * soup->n, normal9, 9 * sizeof(float));
        else for (int i = 0; i < 9; i++) soup->normal[9 * soup->n + i] = NAN;
    }
    for (int s = 0; s < MS_SOUP_UV_SETS; s++) {
        if (uv && uv[s] && !soup->uv[s]) {   /* the set's first triangle: the earlier ones lack it */
            soup->uv[s] = malloc(soup->cap * 6 * sizeof(float));
            if (!soup->uv[s]) return -1;
            for (size_t i = 0; i < 6 * soup->n; i++) soup->uv[s][i] = NAN;
        }
        if (!soup->uv[s]) continue;
        if (uv && uv[s]) memcpy(soup->uv[s] + 6 * soup->n, uv[s], 6 * sizeof(float));
        else for (int i = 0; i < 6; i++) soup->uv[s][6 * soup->n + i] = NAN;
    }
    memcpy(soup->tri + 9 * soup->n, v, 9 * sizeof(float));
    for (int i = 0; i < 9; i++) soup->tri_d[9 * soup->n + i] = vd ? vd[i] : (double)v[i];
    soup->mesh[soup->n] = soup->cur_mesh;
    soup->n++;
    return 0;
}

int ms_soup_push(ms_tri_soup *soup, const float v[9]) { return ms_soup_push_uv(soup, v, NULL); }

void ms_soup_free(ms_tri_soup *soup)
{
    free(soup->tri);
    free(soup->tri_d);
    free(soup->mesh);
    for (int s = 0; s < MS_SOUP_UV_SETS; s++) free(soup->uv[s]);
    free(soup->material);
    free(soup->normal);
    free(soup->tangent);
    free(soup->mats);
    for (size_t i = 0; i < soup->n_tex; i++) free(soup->tex[i].rgba);
    free(soup->tex);
    free(soup->punctual);
    memset(soup, 0, sizeof *soup);
}

static const char *extension(const char *path, char *ext, size_t n)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    ext[0] = 0;
    if (!dot || (slash && dot < slash)) return ext;
    size_t i = 0;
    for (dot++; *dot && i + 1 < n; dot++) ext[i++] = (char)tolower((unsigned char)*dot);
    ext[i] = 0;
    if (*dot) ext[0] = 0;   /* longer than any we know */
    return ext;
}

static int load_memory(const char *buf, size_t len, const char *ext, const char *path, ms_tri_soup *soup,
                       char *err, size_t errlen)
{
    size_t added = 0, before = soup->n;
    int rc;
    if (len == 0) { snprintf(err, errlen, "%s: the mesh file is empty", path); return -1; }
    if (!strcmp(ext, "gltf") || !strcmp(ext, "glb")) {
        rc = ms_mesh_gltf(buf, len, path, soup, &added, err, errlen);
    } else {
        int (*reader)(const char *, size_t, const char *, ms_tri_soup *, size_t *, char *, size_t) =
            !strcmp(ext, "obj") ? ms_mesh_obj : !strcmp(ext, "ply") ? ms_mesh_ply
          : !strcmp(ext, "off") ? ms_mesh_off : !strcmp(ext, "stl") ? ms_mesh_stl : NULL;
        if (!reader) {
            snprintf(err, errlen, "%s: unsupported mesh format '.%s' (microshadow reads .obj, .ply, .off, .stl, "
                     ".gltf, .glb)", path, ext);
            return -1;
        }
        rc = reader(buf, len, path, soup, &added, err, errlen);
    }
    if (rc) { soup->n = before; return -1; }
    if (added == 0) { snprintf(err, errlen, "%s: the mesh has no triangles", path); return -1; }
    for (size_t i = before * 9; i < soup->n * 9; i++)
        if (!isfinite(soup->tri[i])) {
            snprintf(err, errlen, "%s: triangle %zu has a NaN or infinite coordinate", path, i / 9 - before);
            soup->n = before;
            return -1;
        }
    return 0;
}

int ms_mesh_load_memory(const char *buf, size_t len, const char *ext, const char *path, ms_tri_soup *soup,
                        char *err, size_t errlen)
{
    int rc = load_memory(buf, len, ext, path, soup, err, errlen);
    if (rc) ms_one_line(err);
    return rc;
}

int ms_mesh_load(const char *path, ms_tri_soup *soup, char *err, size_t errlen)
{
    char ext[8];
    extension(path, ext, sizeof ext);
    char *buf;
    size_t len;
    if (ms_read_input(path, MS_MAX_MESH_BYTES, MS_INPUT_MESH, &buf, &len, err, errlen)) { ms_one_line(err); return -1; }
    int rc = ms_mesh_load_memory(buf, len, ext, path, soup, err, errlen);
    free(buf);
    return rc;
}
