/* The asset's own emitters as area lights (scene file "lights_from_emissive", docs/lights.md): each emissive
 * triangle becomes a triangle light, and two emissive triangles of one material that together form a
 * parallelogram (a shared edge, the fourth corner where the parallelogram puts it) one rect light. A light
 * emits from its triangles' front face (counter-clockwise, glTF's and OBJ's convention) with the material's
 * emission: glTF emissiveFactor x KHR_materials_emissive_strength, or MTL Ke, times the mean of the
 * emissive texture over the shape (see emitter_radiance).
 *
 * An emitter never shadows its own samples without a special case: they lie in its triangles' plane, where
 * every segment ends (at parameter 1, beyond MS_SEGMENT_FAR), so its triangles stay in every light's
 * occluders and shadow the other lights as any surface does. */
#include "microshadow.h"
#include "scene_internal.h"
#include "../light/light_shape.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Pairing looks at every pair of emissive triangles: bounded so that it stays quick. */
#define PAIRING_MAX 8192

static float srgb_to_linear(uint8_t c)
{
    const float v = (float)c * (1.0f / 255.0f);
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

/* The emissive texture's mean (linear RGB) over triangle t: the nearest texels at the centroids of its 64
 * sub-triangles (UV set of the material, repeat wrap; the sampler's and KHR_texture_transform's settings are
 * not applied: a mean over the shape does not need them to be close). White when there is no texture or
 * the triangle has no UVs. */
static void texture_mean(const ms_scene *s, const ms_material *m, size_t t, float out[3])
{
    out[0] = out[1] = out[2] = 1.0f;
    if (!m->emissive_map || m->emissive_texture < 0 || (size_t)m->emissive_texture >= s->n_textures) return;
    const int set = m->emissive_uv >= 0 && m->emissive_uv < MS_MAX_UV_SETS ? m->emissive_uv : 0;
    const float *uv = s->tri_uv[set] ? s->tri_uv[set] + 6 * t : NULL;
    if (!uv || !isfinite(uv[0]) || !isfinite(uv[2]) || !isfinite(uv[4])) return;
    const ms_texture *tex = &s->textures[m->emissive_texture];
    if (tex->width < 1 || tex->height < 1 || !tex->rgba) return;
    const int n = 8;
    double acc[3] = { 0, 0, 0 };
    int count = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n - i; j++)
            for (int up = 0; up < 2; up++) {
                if (up && i + j + 1 >= n) continue;
                const double a = up ? (i + 2.0 / 3.0) / n : (i + 1.0 / 3.0) / n;
                const double b = up ? (j + 2.0 / 3.0) / n : (j + 1.0 / 3.0) / n;
                double u = uv[0] + a * (uv[2] - uv[0]) + b * (uv[4] - uv[0]);
                double v = uv[1] + a * (uv[3] - uv[1]) + b * (uv[5] - uv[1]);
                u -= floor(u);
                v -= floor(v);
                int x = (int)(u * tex->width), y = (int)(v * tex->height);
                x = x < 0 ? 0 : x >= tex->width ? tex->width - 1 : x;
                y = y < 0 ? 0 : y >= tex->height ? tex->height - 1 : y;
                const uint8_t *px = tex->rgba + 4 * ((size_t)y * (size_t)tex->width + (size_t)x);
                for (int c = 0; c < 3; c++) acc[c] += srgb_to_linear(px[c]);
                count++;
            }
    for (int c = 0; c < 3; c++) out[c] = (float)(acc[c] / count);
}

/* Triangle t's material when it emits, else MS_NO_MATERIAL. */
static uint32_t emitting_material(const ms_scene *s, size_t t)
{
    if (!s->tri_material || !s->materials) return MS_NO_MATERIAL;
    const uint32_t mi = s->tri_material[t];
    if (mi == MS_NO_MATERIAL || mi >= s->n_materials) return MS_NO_MATERIAL;
    const ms_material *m = &s->materials[mi];
    return m->emissive[0] > 0.0f || m->emissive[1] > 0.0f || m->emissive[2] > 0.0f ? mi : MS_NO_MATERIAL;
}

/* Triangle t's emitted radiance into e when it emits and its material is chosen; 0 otherwise. */
static int emitter_radiance(const ms_scene *s, const ms_emitter_choice *choice, size_t t, float e[3])
{
    const uint32_t mi = emitting_material(s, t);
    if (mi == MS_NO_MATERIAL || (choice && choice->lit && !choice->lit[mi])) return 0;
    const ms_material *m = &s->materials[mi];
    float tm[3];
    texture_mean(s, m, t, tm);
    for (int c = 0; c < 3; c++) e[c] = m->emissive[c] * tm[c];
    return e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f;
}

static void vsub(float o[3], const float *a, const float *b) { for (int c = 0; c < 3; c++) o[c] = a[c] - b[c]; }
static int veq(const float *a, const float *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

static void cross(float o[3], const float a[3], const float b[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* Triangle j completes triangle (a, b, c) to the parallelogram a, b, b + c - a, c: it holds b and c exactly,
 * its third vertex is b + c - a within rounding, and it faces the same way. */
static int completes(const float *tj, const float *a, const float *b, const float *c, const float n[3])
{
    int hb = -1, hc = -1;
    for (int k = 0; k < 3; k++) {
        if (veq(tj + 3 * k, b)) hb = k;
        else if (veq(tj + 3 * k, c)) hc = k;
    }
    if (hb < 0 || hc < 0) return 0;
    const float *d = tj + 3 * (3 - hb - hc);
    double off = 0.0, size = 0.0;
    for (int k = 0; k < 3; k++) {
        const double want = (double)b[k] + c[k] - a[k];
        off = fmax(off, fabs(d[k] - want));
        size = fmax(size, fmax(fabs((double)b[k] - a[k]), fabs((double)c[k] - a[k])));
    }
    if (off > 1e-5 * size) return 0;
    float e1[3], e2[3], nj[3];
    vsub(e1, tj + 3, tj);
    vsub(e2, tj + 6, tj);
    cross(nj, e1, e2);
    return (double)nj[0] * n[0] + (double)nj[1] * n[1] + (double)nj[2] * n[2] > 0.0;
}

size_t ms_scene_emissive_triangles(const ms_scene *s, const ms_emitter_choice *choice)
{
    size_t n = 0;
    float e[3];
    for (size_t t = 0; s->tri && t < s->n_tris; t++) n += emitter_radiance(s, choice, t, e);
    return n;
}

void ms_scene_emissive_materials_text(const ms_scene *s, char *const *names, char *buf, size_t n)
{
    if (n) buf[0] = '\0';
    size_t *count = s->n_materials ? calloc(s->n_materials, sizeof *count) : NULL;
    if (!count) return;
    for (size_t t = 0; s->tri && t < s->n_tris; t++) {
        const uint32_t mi = emitting_material(s, t);
        if (mi != MS_NO_MATERIAL) count[mi]++;
    }
    size_t used = 0, shown = 0, left = 0;
    for (;;) {   /* the most triangles first: a few passes over a short list */
        size_t best = SIZE_MAX;
        for (size_t m = 0; m < s->n_materials; m++)
            if (count[m] && (best == SIZE_MAX || count[m] > count[best])) best = m;
        if (best == SIZE_MAX) break;
        if (shown == 6) { left++; count[best] = 0; continue; }
        char label[160];
        if (names && names[best]) snprintf(label, sizeof label, "\"%.120s\"", names[best]);
        else snprintf(label, sizeof label, "material %zu (no name)", best);
        const int w = snprintf(buf + used, used < n ? n - used : 0, "%s%s: %zu triangle%s", shown ? ", " : "", label,
                               count[best], count[best] > 1 ? "s" : "");
        if (w > 0) used += (size_t)w;
        shown++;
        count[best] = 0;
    }
    if (left && used < n) snprintf(buf + used, n - used, " and %zu more", left);
    free(count);
}

/* The ways out of too many emitters, for the error lines below. */
static void too_many(const ms_scene *s, const ms_emitter_choice *choice, const char *what, size_t room, const char *path,
                     char *err, size_t errlen)
{
    char mats[512];
    ms_scene_emissive_materials_text(s, choice ? choice->names : NULL, mats, sizeof mats);
    snprintf(err, errlen, "%s: %s, more than the %zu a frame can still hold (%d in all; emissive materials: %s): list the "
             "materials that are lamps, \"lights_from_emissive\": [\"name\", ...] (the others still glow), or set "
             "\"lights_from_emissive\": false and name the lights in the scene file, or raise MS_MAX_LIGHTS "
             "(src/scene/scene_internal.h)", path, what, room, MS_MAX_LIGHTS, mats);
}

int ms_scene_emitter_lights(const ms_scene *s, const ms_emitter_choice *choice, size_t room, const char *path,
                            ms_light **out, size_t *n_out, char *err, size_t errlen)
{
    *out = NULL;
    *n_out = 0;
    if (!s->tri || !s->tri_material) return 0;
    size_t n_e = 0;
    float e[3];
    for (size_t t = 0; t < s->n_tris; t++) n_e += emitter_radiance(s, choice, t, e);
    if (!n_e) return 0;
    if (n_e > PAIRING_MAX || (n_e + 1) / 2 > room) {
        char what[160];
        snprintf(what, sizeof what, "the meshes have %zu emissive triangles to make lights of, at least %zu lights", n_e,
                 (n_e + 1) / 2);
        too_many(s, choice, what, room, path, err, errlen);
        return -1;
    }
    size_t *idx = malloc(n_e * sizeof *idx);
    unsigned char *used = calloc(n_e, 1);
    ms_light *L = calloc(n_e, sizeof *L);
    if (!idx || !used || !L) {
        free(idx); free(used); free(L);
        snprintf(err, errlen, "%s: out of memory for the emissive triangles' lights", path);
        return -1;
    }
    n_e = 0;
    for (size_t t = 0; t < s->n_tris; t++)
        if (emitter_radiance(s, choice, t, e)) idx[n_e++] = t;
    size_t n = 0;
    for (size_t i = 0; i < n_e; i++) {
        if (used[i]) continue;
        used[i] = 1;
        const float *ti = s->tri + 9 * idx[i];
        float ei[3], e1[3], e2[3], nrm[3];
        emitter_radiance(s, choice, idx[i], ei);
        vsub(e1, ti + 3, ti);
        vsub(e2, ti + 6, ti);
        cross(nrm, e1, e2);
        if (!(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2] > 0.0f)) continue;   /* degenerate: emits nothing */
        ms_light *l = &L[n];
        memset(l, 0, sizeof *l);
        int paired = 0;
        for (int r = 0; r < 3 && !paired; r++) {
            const float *a = ti + 3 * r, *b = ti + 3 * ((r + 1) % 3), *c = ti + 3 * ((r + 2) % 3);
            for (size_t j = i + 1; j < n_e && !paired; j++) {
                if (used[j] || s->tri_material[idx[j]] != s->tri_material[idx[i]]) continue;
                if (!completes(s->tri + 9 * idx[j], a, b, c, nrm)) continue;
                float ej[3];
                emitter_radiance(s, choice, idx[j], ej);
                /* cross(b - a, c - a) is the front face's normal for every rotation of (a, b, c) */
                l->corner = (ms_vec3){ a[0], a[1], a[2] };
                l->edge_s = (ms_vec3){ b[0] - a[0], b[1] - a[1], b[2] - a[2] };
                l->edge_t = (ms_vec3){ c[0] - a[0], c[1] - a[1], c[2] - a[2] };
                l->shape = MS_LIGHT_RECT;
                /* the two halves have equal areas: the mean of their (texture-weighted) emissions */
                l->emission = (ms_vec3){ 0.5f * (ei[0] + ej[0]), 0.5f * (ei[1] + ej[1]), 0.5f * (ei[2] + ej[2]) };
                used[j] = 1;
                paired = 1;
            }
        }
        if (!paired) {
            ms_light_triangle(l, (ms_vec3){ ti[0], ti[1], ti[2] }, (ms_vec3){ ti[3], ti[4], ti[5] },
                              (ms_vec3){ ti[6], ti[7], ti[8] });
            l->emission = (ms_vec3){ ei[0], ei[1], ei[2] };
        }
        n++;
    }
    free(idx);
    free(used);
    if (n > room) {
        free(L);
        char what[160];
        snprintf(what, sizeof what, "the meshes' emissive triangles make %zu lights", n);
        too_many(s, choice, what, room, path, err, errlen);
        return -1;
    }
    if (!n) { free(L); return 0; }
    *out = L;
    *n_out = n;
    return 0;
}
