/* The triangle soup the mesh readers fill (scene_internal.h, ms_tri_soup): triangles with their
 * double-precision positions, mesh, UV sets, material and normals appended together, and freed together.
 * Below every reader (mesh_obj.c, mesh_ply.c, mesh_gltf.c, ...) and the dispatcher above them
 * (mesh_load.c), so that neither depends on the other. */
#include "scene_internal.h"
#include "microshadow.h"
#include <math.h>
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
        uint32_t *o = realloc(soup->object, cap * sizeof *o);
        if (!o) return -1;
        soup->object = o;
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
    if (!soup->n_objects) soup->n_objects = 1;   /* object 0 for loaders that never start one */
    soup->object[soup->n] = soup->cur_object;
    soup->object_used = 1;
    soup->n++;
    return 0;
}

void ms_soup_new_object(ms_tri_soup *soup)
{
    if (soup->object_used || !soup->n_objects) soup->cur_object = soup->n_objects++;
    soup->object_used = 0;
}

int ms_soup_push(ms_tri_soup *soup, const float v[9]) { return ms_soup_push_uv(soup, v, NULL); }

void ms_soup_free(ms_tri_soup *soup)
{
    free(soup->tri);
    free(soup->tri_d);
    free(soup->mesh);
    free(soup->object);
    for (int s = 0; s < MS_SOUP_UV_SETS; s++) free(soup->uv[s]);
    free(soup->material);
    free(soup->normal);
    free(soup->tangent);
    ms_soup_free_names(soup);
    free(soup->mats);
    for (size_t i = 0; i < soup->n_tex; i++) free(soup->tex[i].rgba);
    free(soup->tex);
    free(soup->punctual);
    memset(soup, 0, sizeof *soup);
}
