/* The built-in scenes, generated in code (no file needed).
 * ms_scene_default: a ground, occluders of several sizes and heights (a tall pillar, a cube, a floating open
 * plate, a faceted sphere) under one square light, so that both hard contact shadows and wide penumbrae show:
 * the tests' fixture, kept as it is.
 * ms_scene_showcase: the CLI's picture without a scene file (the README's first image): smooth-shaded
 * curved objects (per-vertex normals), a textured ground, a metal and rough plastics, alpha-tested leaf
 * cards, lit by a rect, a disk and a sphere light of different colours. */
#include "microshadow.h"
#include "../core/abi.h"
#include "scene_internal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int quad(ms_tri_soup *s, const float a[3], const float b[3], const float c[3], const float d[3])
{
    float t0[9] = { a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2] };
    float t1[9] = { a[0], a[1], a[2], c[0], c[1], c[2], d[0], d[1], d[2] };
    return ms_soup_push(s, t0) || ms_soup_push(s, t1);
}

static int box(ms_tri_soup *s, float x0, float y0, float z0, float x1, float y1, float z1)
{
    float p[8][3];
    for (int i = 0; i < 8; i++) {
        p[i][0] = (i & 1) ? x1 : x0;
        p[i][1] = (i & 2) ? y1 : y0;
        p[i][2] = (i & 4) ? z1 : z0;
    }
    static const int f[6][4] = { { 0, 1, 3, 2 }, { 4, 6, 7, 5 }, { 0, 4, 5, 1 },
                                 { 2, 3, 7, 6 }, { 0, 2, 6, 4 }, { 1, 5, 7, 3 } };
    for (int i = 0; i < 6; i++)
        if (quad(s, p[f[i][0]], p[f[i][1]], p[f[i][2]], p[f[i][3]])) return -1;
    return 0;
}

static int sphere(ms_tri_soup *s, float cx, float cy, float cz, float r, int rings, int segs)
{
    for (int i = 0; i < rings; i++) {
        float th0 = (float)M_PI * (float)i / (float)rings, th1 = (float)M_PI * (float)(i + 1) / (float)rings;
        for (int j = 0; j < segs; j++) {
            float ph0 = 2.0f * (float)M_PI * (float)j / (float)segs;
            float ph1 = 2.0f * (float)M_PI * (float)(j + 1) / (float)segs;
            float q[4][3];
            const float th[4] = { th0, th0, th1, th1 }, ph[4] = { ph0, ph1, ph1, ph0 };
            for (int k = 0; k < 4; k++) {
                q[k][0] = cx + r * sinf(th[k]) * cosf(ph[k]);
                q[k][1] = cy + r * cosf(th[k]);
                q[k][2] = cz + r * sinf(th[k]) * sinf(ph[k]);
            }
            if (quad(s, q[0], q[1], q[2], q[3])) return -1;
        }
    }
    return 0;
}

ms_status ms_scene_default_abi(const ms_abi *abi, ms_scene *out)
{
    char msg[256];
    if (ms_abi_check(abi, "ms_scene_default", msg, sizeof msg)) { ms_warn("%s", msg); return MS_ERR_INVALID; }
    memset(out, 0, sizeof *out);
    ms_tri_soup s = { 0 };
    const float g0[3] = { -8, 0, -8 }, g1[3] = { 8, 0, -8 }, g2[3] = { 8, 0, 8 }, g3[3] = { -8, 0, 8 };
    const float p0[3] = { -0.9f, 1.6f, 1.4f }, p1[3] = { 0.3f, 1.6f, 1.4f }, p2[3] = { 0.3f, 1.6f, 2.6f },
                p3[3] = { -0.9f, 1.6f, 2.6f };
    if (quad(&s, g0, g3, g2, g1) ||
        box(&s, -3.2f, 0.0f, -0.6f, -2.8f, 3.5f, -0.2f) ||      /* tall thin pillar */
        box(&s, 1.5f, 0.0f, -1.5f, 3.0f, 1.5f, 0.0f) ||         /* cube on the ground */
        quad(&s, p0, p1, p2, p3) ||                             /* floating open plate */
        sphere(&s, -0.8f, 0.9f, -2.6f, 0.9f, 24, 48)) {         /* sphere resting on the ground */
        ms_soup_free(&s);
        return MS_ERR_NO_MEMORY;
    }
    free(s.tri_d);   /* generated about the origin: the scene's frame is the world's */
    out->tri = s.tri;
    out->n_tris = s.n;
    out->tri_mesh = s.mesh;
    out->n_meshes = 1;
    out->tri_object = s.object;
    out->n_objects = s.n_objects;
    out->camera = (ms_camera){ { 0.0f, 6.5f, 10.0f }, { 0.0f, 0.6f, 0.0f }, { 0.0f, 1.0f, 0.0f }, 50.0f, 1024, 768, MS_CAMERA_PINHOLE, 0.0f, 0.0f };
    out->light = (ms_light){ { -1.25f, 6.0f, -1.25f }, { 2.5f, 0.0f, 0.0f }, { 0.0f, 0.0f, 2.5f },
                             { MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION, MS_DEFAULT_EMISSION }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
    out->samples = 1024;
    return MS_OK;
}

/* ---- The showcase scene ---- */

/* A triangle with its UVs (NULL: none), material and vertex normals (NULL: the face's). */
static int tri_full(ms_tri_soup *s, const float a[3], const float b[3], const float c[3], const float *uv6, uint32_t mat,
                    const float *na, const float *nb, const float *nc)
{
    const float v[9] = { a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2] };
    const float *uv[MS_SOUP_UV_SETS] = { uv6, NULL, NULL, NULL };
    float n[9];
    if (na)
        for (int k = 0; k < 3; k++) { n[k] = na[k]; n[3 + k] = nb[k]; n[6 + k] = nc[k]; }
    return ms_soup_push_full(s, v, uv, mat, na ? n : NULL);
}

/* A quad a b c d (counter-clockwise seen from its front) with UVs (0,0) (1,0) (1,1) (0,1) times uv_scale. */
static int quad_uv(ms_tri_soup *s, const float a[3], const float b[3], const float c[3], const float d[3], float uv_scale,
                   uint32_t mat)
{
    const float u = uv_scale;
    const float uv0[6] = { 0, 0, u, 0, u, u }, uv1[6] = { 0, 0, u, u, 0, u };
    return tri_full(s, a, b, c, uv0, mat, NULL, NULL, NULL) || tri_full(s, a, c, d, uv1, mat, NULL, NULL, NULL);
}

/* A surface of revolution-like grid: point and normal at (u, v) in [0,1]^2 by fn, rows x cols quads,
 * smooth-shaded. */
typedef void (*surface_fn)(const float *prm, float u, float v, float p[3], float n[3]);

static int smooth_grid(ms_tri_soup *s, surface_fn fn, const float *prm, int rows, int cols, uint32_t mat)
{
    for (int i = 0; i < rows; i++)
        for (int j = 0; j < cols; j++) {
            float p[4][3], n[4][3];
            const float us[4] = { (float)j / cols, (float)(j + 1) / cols, (float)(j + 1) / cols, (float)j / cols };
            const float vs[4] = { (float)i / rows, (float)i / rows, (float)(i + 1) / rows, (float)(i + 1) / rows };
            for (int k = 0; k < 4; k++) fn(prm, us[k], vs[k], p[k], n[k]);
            if (tri_full(s, p[0], p[1], p[2], NULL, mat, n[0], n[1], n[2]) ||
                tri_full(s, p[0], p[2], p[3], NULL, mat, n[0], n[2], n[3]))
                return -1;
        }
    return 0;
}

/* prm: centre x, y, z, radius. v from the top pole down (so that the quads face outwards). */
static void sphere_at(const float *prm, float u, float v, float p[3], float n[3])
{
    const float th = (float)M_PI * v, ph = -2.0f * (float)M_PI * u;
    n[0] = sinf(th) * cosf(ph);
    n[1] = cosf(th);
    n[2] = sinf(th) * sinf(ph);
    for (int k = 0; k < 3; k++) p[k] = prm[k] + prm[3] * n[k];
}

/* prm: centre x, y, z, major radius R, minor radius r; lying in the xz plane. */
static void torus_at(const float *prm, float u, float v, float p[3], float n[3])
{
    const float ph = -2.0f * (float)M_PI * u, th = 2.0f * (float)M_PI * v;
    const float c = cosf(ph), s = sinf(ph);
    n[0] = cosf(th) * c;
    n[1] = sinf(th);
    n[2] = cosf(th) * s;
    p[0] = prm[0] + (prm[3] + prm[4] * cosf(th)) * c;
    p[1] = prm[1] + prm[4] * sinf(th);
    p[2] = prm[2] + (prm[3] + prm[4] * cosf(th)) * s;
}

/* prm: base centre x, y, z, radius, height: the side of a vertical cylinder (v from the top down). */
static void cylinder_at(const float *prm, float u, float v, float p[3], float n[3])
{
    const float ph = -2.0f * (float)M_PI * u;
    n[0] = cosf(ph);
    n[1] = 0.0f;
    n[2] = sinf(ph);
    p[0] = prm[0] + prm[3] * n[0];
    p[1] = prm[1] + prm[4] * (1.0f - v);
    p[2] = prm[2] + prm[3] * n[2];
}

/* The cylinder's top cap, a fan facing up. */
static int cylinder_cap(ms_tri_soup *s, const float *prm, int segs, uint32_t mat)
{
    const float c[3] = { prm[0], prm[1] + prm[4], prm[2] };
    for (int j = 0; j < segs; j++) {
        const float a0 = 2.0f * (float)M_PI * (float)j / segs, a1 = 2.0f * (float)M_PI * (float)(j + 1) / segs;
        const float p0[3] = { c[0] + prm[3] * cosf(a0), c[1], c[2] + prm[3] * sinf(a0) };
        const float p1[3] = { c[0] + prm[3] * cosf(a1), c[1], c[2] + prm[3] * sinf(a1) };
        if (tri_full(s, c, p1, p0, NULL, mat, NULL, NULL, NULL)) return -1;
    }
    return 0;
}

static int box_mat(ms_tri_soup *s, float x0, float y0, float z0, float x1, float y1, float z1, uint32_t mat)
{
    float p[8][3];
    for (int i = 0; i < 8; i++) {
        p[i][0] = (i & 1) ? x1 : x0;
        p[i][1] = (i & 2) ? y1 : y0;
        p[i][2] = (i & 4) ? z1 : z0;
    }
    static const int f[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 },
                                 { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
    for (int i = 0; i < 6; i++)
        if (quad_uv(s, p[f[i][0]], p[f[i][1]], p[f[i][2]], p[f[i][3]], 1.0f, mat)) return -1;
    return 0;
}

/* The ground's texture: stone tiles (sRGB), a warm and a cool grey in a checker, with a little per-tile
 * variation and dark grout between them. One tile per texture repeat. */
static int ground_texture(ms_texture *t)
{
    const int n = 128;
    t->width = t->height = n;
    t->rgba = malloc((size_t)n * n * 4);
    if (!t->rgba) return -1;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            uint8_t *px = t->rgba + 4 * ((size_t)y * n + x);
            const int tile = (x < n / 2) ^ (y < n / 2);
            const int gx = x % (n / 2), gy = y % (n / 2);
            const int grout = gx < 2 || gy < 2;
            /* A deterministic speckle: hashed texel coordinates. */
            unsigned h = (unsigned)x * 73856093u ^ (unsigned)y * 19349663u;
            h = (h ^ (h >> 13)) * 0x5bd1e995u;
            const int speckle = (int)((h >> 24) & 15) - 8;
            int r = tile ? 178 : 140, g = tile ? 166 : 140, b = tile ? 146 : 150;
            if (grout) r = g = b = 70;
            px[0] = (uint8_t)(r + speckle);
            px[1] = (uint8_t)(g + speckle);
            px[2] = (uint8_t)(b + speckle);
            px[3] = 255;
        }
    return 0;
}

/* A leaf (sRGB colour, alpha 0 outside it): a pointed ellipse along v with a lighter midrib. */
static int leaf_texture(ms_texture *t)
{
    const int n = 64;
    t->width = t->height = n;
    t->rgba = malloc((size_t)n * n * 4);
    if (!t->rgba) return -1;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            uint8_t *px = t->rgba + 4 * ((size_t)y * n + x);
            const float u = ((float)x + 0.5f) / n * 2.0f - 1.0f, v = ((float)y + 0.5f) / n;
            const float half_width = 0.85f * sinf((float)M_PI * v) * (0.6f + 0.4f * v);   /* wider near the tip end */
            const int inside = fabsf(u) < half_width && v > 0.04f && v < 0.98f;
            const int rib = fabsf(u) < 0.05f || (fabsf(fabsf(u) - (v - 0.2f) * 0.9f) < 0.04f && fmodf(v * 5.0f, 1.0f) < 0.5f);
            px[0] = (uint8_t)(rib ? 120 : 70);
            px[1] = (uint8_t)(rib ? 170 : 130 + (int)(40.0f * v));
            px[2] = (uint8_t)(rib ? 70 : 40);
            px[3] = inside ? 255 : 0;
        }
    return 0;
}

enum { MAT_GROUND, MAT_GOLD, MAT_RED, MAT_BLUE, MAT_WHITE, MAT_LEAF, N_MATS };

ms_status ms_scene_showcase_abi(const ms_abi *abi, ms_scene *out)
{
    char msg[256];
    if (ms_abi_check(abi, "ms_scene_showcase", msg, sizeof msg)) { ms_warn("%s", msg); return MS_ERR_INVALID; }
    memset(out, 0, sizeof *out);
    ms_tri_soup s = { 0 };
    ms_texture *tex = calloc(2, sizeof *tex);
    ms_light *lights = calloc(3, sizeof *lights);
    int failed = !tex || !lights || ground_texture(&tex[0]) || leaf_texture(&tex[1]);
    /* Materials (linear base colours): a textured rough ground, a polished gold, rough red and blue
     * plastics, a white satin, and the alpha-tested leaves. */
    const ms_material base = { .base_color = { 1, 1, 1, 1 }, .roughness = 0.6f, .base_color_texture = -1,
                               .alpha_cutoff = 0.5f, .alpha_texture = -1 };
    ms_material m[N_MATS];
    for (int i = 0; i < N_MATS; i++) m[i] = base;
    m[MAT_GROUND].base_color_texture = 0;
    m[MAT_GROUND].roughness = 0.9f;
    m[MAT_GOLD] = (ms_material){ .base_color = { 1.0f, 0.71f, 0.29f, 1 }, .metallic = 1.0f, .roughness = 0.45f,
                                 .base_color_texture = -1, .alpha_cutoff = 0.5f, .alpha_texture = -1 };
    m[MAT_RED].base_color[0] = 0.62f; m[MAT_RED].base_color[1] = 0.06f; m[MAT_RED].base_color[2] = 0.05f;
    m[MAT_RED].roughness = 0.55f;
    m[MAT_BLUE].base_color[0] = 0.08f; m[MAT_BLUE].base_color[1] = 0.18f; m[MAT_BLUE].base_color[2] = 0.55f;
    m[MAT_BLUE].roughness = 0.7f;
    m[MAT_WHITE].base_color[0] = m[MAT_WHITE].base_color[1] = m[MAT_WHITE].base_color[2] = 0.75f;
    m[MAT_WHITE].roughness = 0.4f;
    m[MAT_LEAF].base_color_texture = 1;
    m[MAT_LEAF].alpha_mode = MS_ALPHA_MASK;
    m[MAT_LEAF].roughness = 0.8f;
    for (int i = 0; i < N_MATS && !failed; i++) failed = ms_soup_add_material(&s, &m[i], NULL) != i;

    const float g0[3] = { -8, 0, 8 }, g1[3] = { 8, 0, 8 }, g2[3] = { 8, 0, -8 }, g3[3] = { -8, 0, -8 };
    const float gold[4] = { -0.4f, 1.0f, -0.6f, 1.0f };
    const float torus[5] = { 2.3f, 0.32f, 1.2f, 0.85f, 0.32f };
    const float pillar[5] = { -3.0f, 0.0f, -1.2f, 0.35f, 3.2f };
    failed = failed || quad_uv(&s, g0, g1, g2, g3, 8.0f, MAT_GROUND) ||
             smooth_grid(&s, sphere_at, gold, 32, 64, MAT_GOLD) ||
             smooth_grid(&s, torus_at, torus, 24, 64, MAT_RED) ||
             smooth_grid(&s, cylinder_at, pillar, 1, 48, MAT_BLUE) || cylinder_cap(&s, pillar, 48, MAT_BLUE) ||
             box_mat(&s, 1.4f, 0.0f, -2.6f, 2.6f, 1.2f, -1.4f, MAT_WHITE);
    /* Leaf cards hanging over the front left, their dappled shadows on the ground: each a quad of the leaf
     * texture, turned and tilted. */
    for (int i = 0; i < 10 && !failed; i++) {
        const float a = 2.4f * (float)i, r = 0.25f + 0.09f * (float)i;
        const float cx = -2.0f + r * cosf(a), cy = 1.5f + 0.12f * sinf(2.9f * (float)i), cz = 2.4f + r * sinf(a),
                    len = 1.0f, wid = 0.6f;
        /* The leaf's axis mostly horizontal, turned by a; its width tilted up and down. */
        const float ax[3] = { cosf(a) * len, 0.25f * sinf(2.0f * a) * len, sinf(a) * len };
        const float wx[3] = { -sinf(a) * wid, 0.35f * wid * cosf(3.0f * a), cosf(a) * wid };
        float p[4][3];
        const float c[3] = { cx, cy, cz };
        for (int k = 0; k < 3; k++) {
            p[0][k] = c[k] - 0.5f * wx[k];
            p[1][k] = c[k] + 0.5f * wx[k];
            p[2][k] = c[k] + 0.5f * wx[k] + ax[k];
            p[3][k] = c[k] - 0.5f * wx[k] + ax[k];
        }
        failed = quad_uv(&s, p[0], p[1], p[2], p[3], 1.0f, MAT_LEAF);
    }
    if (!failed) {
        /* A warm rect overhead, a cool disk to the right, an orange sphere low at the back left. */
        lights[0] = (ms_light){ { -2.0f, 6.0f, -1.5f }, { 2.2f, 0.0f, 0.0f }, { 0.0f, 0.0f, 2.2f },
                                { 1.0f, 0.9f, 0.75f }, MS_LIGHT_RECT, NULL, 0, 0, { 0, 0, 0 }, 0 };
        lights[1].emission = (ms_vec3){ 0.45f, 0.65f, 1.6f };
        lights[2].emission = (ms_vec3){ 3.0f, 1.3f, 0.35f };
        failed = ms_light_disk(&lights[1], (ms_vec3){ 4.5f, 3.5f, 2.0f }, (ms_vec3){ -1.0f, -0.9f, -0.5f }, 0.7f) ||
                 ms_light_sphere(&lights[2], (ms_vec3){ -2.2f, 1.6f, -3.2f }, 0.3f);
    }
    if (failed) {
        ms_soup_free(&s);
        for (int i = 0; tex && i < 2; i++) free(tex[i].rgba);
        free(tex);
        free(lights);
        return MS_ERR_NO_MEMORY;
    }
    free(s.tri_d);   /* generated about the origin: the scene's frame is the world's */
    ms_soup_free_names(&s);
    out->tri = s.tri;
    out->n_tris = s.n;
    out->tri_mesh = s.mesh;
    out->n_meshes = 1;
    out->tri_object = s.object;
    out->n_objects = s.n_objects;
    for (int i = 0; i < MS_MAX_UV_SETS; i++) out->tri_uv[i] = s.uv[i];
    out->materials = s.mats;
    out->n_materials = s.n_mats;
    out->tri_material = s.material;
    out->tri_normal = s.normal;
    out->textures = tex;
    out->n_textures = 2;
    out->lights = lights;
    out->n_lights = 3;
    out->light = lights[0];
    out->camera = (ms_camera){ { 0.0f, 5.0f, 9.5f }, { 0.0f, 0.9f, 0.0f }, { 0.0f, 1.0f, 0.0f }, 45.0f, 768, 512, MS_CAMERA_PINHOLE, 0.0f, 0.0f };
    out->samples = 256;
    return MS_OK;
}
