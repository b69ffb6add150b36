/* Tangents for normal maps: MikkTSpace (third_party/mikktspace, the reference implementation glTF names)
 * over the triangles of one glTF primitive, or the asset's own TANGENT attribute, stored per triangle
 * vertex in the soup (12 floats: x, y, z, w per vertex; NaN for triangles without). */
#include "scene_internal.h"
#include "microshadow.h"
#include "mikktspace.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

int ms_soup_set_tangents(ms_tri_soup *soup, size_t first, size_t count, const float *t12)
{
    const size_t end = first + count;
    if (end > soup->tangent_n) {
        float *t = realloc(soup->tangent, end * 12 * sizeof *t);
        if (!t) return -1;
        for (size_t i = 12 * soup->tangent_n; i < 12 * end; i++) t[i] = NAN;
        soup->tangent = t;
        soup->tangent_n = end;
    }
    memcpy(soup->tangent + 12 * first, t12, count * 12 * sizeof *t12);
    return 0;
}

float *ms_soup_take_tangents(ms_tri_soup *soup)
{
    float *t = soup->tangent;
    if (t && soup->tangent_n < soup->n) {   /* the triangles after the last with tangents: none */
        float *g = realloc(t, soup->n * 12 * sizeof *g);
        if (!g) { free(t); t = NULL; }
        else {
            for (size_t i = 12 * soup->tangent_n; i < 12 * soup->n; i++) g[i] = NAN;
            t = g;
        }
    }
    soup->tangent = NULL;
    soup->tangent_n = 0;
    return t;
}

typedef struct mikk_user {
    const ms_tri_soup *soup;
    size_t first;
    int count, set;
    float *out;
    int far;        /* the primitive lies far from the origin: positions from tri_d - o (scene_frame.c) */
    double o[3];
} mikk_user;

static int n_faces(const SMikkTSpaceContext *c) { return ((const mikk_user *)c->m_pUserData)->count; }
static int n_verts(const SMikkTSpaceContext *c, const int f) { (void)c; (void)f; return 3; }

static void get_pos(const SMikkTSpaceContext *c, float out[], const int f, const int v)
{
    const mikk_user *u = c->m_pUserData;
    const size_t i = 9 * (u->first + (size_t)f) + 3 * (size_t)v;
    if (u->far) ms_scene_frame_point(u->soup->tri_d + i, u->o, out);
    else memcpy(out, u->soup->tri + i, 3 * sizeof(float));
}

/* The vertex normal, or the face normal where the mesh has none (glTF: flat shading). */
static void get_normal(const SMikkTSpaceContext *c, float out[], const int f, const int v)
{
    const mikk_user *u = c->m_pUserData;
    const size_t t = u->first + (size_t)f;
    const float *n = u->soup->normal ? u->soup->normal + 9 * t + 3 * v : NULL;
    if (n && isfinite(n[0]) && isfinite(n[1]) && isfinite(n[2])) { memcpy(out, n, 3 * sizeof(float)); return; }
    float p[9];
    for (int k = 0; k < 3; k++) get_pos(c, p + 3 * k, f, k);
    const float e1[3] = { p[3] - p[0], p[4] - p[1], p[5] - p[2] }, e2[3] = { p[6] - p[0], p[7] - p[1], p[8] - p[2] };
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const float l = sqrtf(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (int k = 0; k < 3 && l > 0.0f; k++) out[k] /= l;
}

/* (u, 1 - v): glTF's v runs down the image while its normal maps' +Y points up the image (OpenGL's
 * convention, the one MikkTSpace's bitangent sign encodes for textures with v up). */
static void get_uv(const SMikkTSpaceContext *c, float out[], const int f, const int v)
{
    const mikk_user *u = c->m_pUserData;
    const float *uv = u->soup->uv[u->set] + 6 * (u->first + (size_t)f) + 2 * v;
    out[0] = uv[0];
    out[1] = 1.0f - uv[1];
}

static void set_basic(const SMikkTSpaceContext *c, const float t[], const float sign, const int f, const int v)
{
    const mikk_user *u = c->m_pUserData;
    float *o = u->out + 12 * (size_t)f + 4 * (size_t)v;
    o[0] = t[0];
    o[1] = t[1];
    o[2] = t[2];
    o[3] = sign < 0.0f ? -1.0f : 1.0f;
}

int ms_soup_mikktspace(ms_tri_soup *soup, size_t first, size_t count, int set)
{
    if (count == 0 || count > (size_t)(INT32_MAX / 3) || set < 0 || set >= MS_SOUP_UV_SETS || !soup->uv[set]) return 0;
    /* Only finite, bounded input (the scene's validation refuses the rest later; MikkTSpace would convert
     * NaN to int when it sorts vertices into cells). */
    float lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (size_t i = 9 * first; i < 9 * (first + count); i++) {
        if (!(fabsf(soup->tri[i]) <= MS_MAX_COORD)) return 0;
        lo[i % 3] = fminf(lo[i % 3], soup->tri[i]);
        hi[i % 3] = fmaxf(hi[i % 3], soup->tri[i]);
    }
    /* Every vertex at one point: MikkTSpace's vertex grid divides by the extent, 0/0 (found by fuzz_gltf);
     * such a primitive has no area to shade anyway. */
    if (hi[0] == lo[0] && hi[1] == lo[1] && hi[2] == lo[2]) return 0;
    for (size_t i = 6 * first; i < 6 * (first + count); i++)
        if (!(fabsf(soup->uv[set][i]) <= 1e18f)) return 0;
    for (size_t i = 9 * first; soup->normal && i < 9 * (first + count); i++)
        if (isinf(soup->normal[i])) return 0;
    mikk_user u = { soup, first, (int)count, set, malloc(count * 12 * sizeof(float)), 0, { 0, 0, 0 } };
    if (!u.out) return -1;
    /* Tangents depend on position differences: far from the origin, from the double positions in the
     * primitive's own frame (the floats there are too coarse); else from the floats, as always. */
    if (soup->tri_d) {
        ms_scene_frame_origin(soup->tri_d + 9 * first, count, u.o);
        u.far = u.o[0] != 0.0 || u.o[1] != 0.0 || u.o[2] != 0.0;
    }
    for (size_t i = 0; i < 12 * count; i++) u.out[i] = NAN;
    SMikkTSpaceInterface mi = { n_faces, n_verts, get_pos, get_normal, get_uv, set_basic, NULL };
    SMikkTSpaceContext ctx = { &mi, &u };
    int rc = 0;
    if (genTangSpaceDefault(&ctx)) rc = ms_soup_set_tangents(soup, first, count, u.out);
    free(u.out);
    return rc;
}
