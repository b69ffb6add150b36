/* The bake back onto the asset (microshadow/bake.h, "The bake back onto the asset"): the scene's triangles, their
 * materials and textures, TEXCOORD_1 = the baked UVs, the lightmap (MOZ_lightmap) and the shadowmask, as one
 * binary glTF 2.0. The JSON is built with cJSON; the binary chunk is ours: every accessor and image in one
 * buffer, each view aligned to 4 bytes. */
#include "microshadow.h"
#include "core/abi.h"
#include "image/png_encode.h"
#include "scene/scene_internal.h"
#include "shade.h"
#include "bake_unbaked.h"
#include "frame_shade.h"
#include "light/light_shape.h"
#include "bake_gltf_pages.h"
#include "bake_gltf_lights.h"
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { GL_FLOAT = 5126, GL_UNSIGNED_INT = 5125, GL_ARRAY_BUFFER = 34962, GL_ELEMENT_ARRAY_BUFFER = 34963,
       GL_NEAREST = 9728, GL_LINEAR = 9729, GL_LINEAR_MIPMAP_LINEAR = 9987, GL_REPEAT = 10497,
       GL_CLAMP_TO_EDGE = 33071, GL_MIRRORED_REPEAT = 33648 };

/* The binary chunk as it grows. */
typedef struct bin {
    unsigned char *p;
    size_t n, cap;
    int oom;
} bin;

/* Appends n bytes at a 4-byte boundary; their offset. */
static size_t bin_put(bin *b, const void *src, size_t n)
{
    const size_t at = (b->n + 3) & ~(size_t)3;
    if (at + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < at + n) cap *= 2;
        unsigned char *q = realloc(b->p, cap);
        if (!q) { b->oom = 1; return 0; }
        b->p = q;
        b->cap = cap;
    }
    memset(b->p + b->n, 0, at - b->n);
    if (n) memcpy(b->p + at, src, n);
    b->n = at + n;
    return at;
}

typedef struct writer {
    const ms_scene *sc;
    const ms_lightmap *lm;
    ms_bake_gltf_options opt;
    cJSON *root, *views, *accessors, *images, *textures, *samplers, *materials, *meshes, *nodes;
    bin bin;
    int *image_of;          /* scene texture -> glTF image, -1 until made */
    int *lightmap_tex, *shadowmask_tex;   /* per lightmap page */
    int pages;
    double intensity;       /* the lightmap's scale I */
    int *material_of;       /* (((scene material + 1) * 4 + variant) * MS_UNBAKED_REASONS + reason) * pages + page ->
                             * glTF material, -1 until made */
    int used_emissive_strength, dropped_transform, dropped_uv_set;
    char *err;
    size_t errlen;
} writer;

/* A bufferView of n bytes (target 0: none) and its index. */
static int add_view(writer *w, const void *data, size_t n, int target)
{
    const size_t off = bin_put(&w->bin, data, n);
    cJSON *v = cJSON_CreateObject();
    cJSON_AddNumberToObject(v, "buffer", 0);
    cJSON_AddNumberToObject(v, "byteOffset", (double)off);
    cJSON_AddNumberToObject(v, "byteLength", (double)n);
    if (target) cJSON_AddNumberToObject(v, "target", target);
    cJSON_AddItemToArray(w->views, v);
    return cJSON_GetArraySize(w->views) - 1;
}

static cJSON *num_array(const float *x, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; i < n; i++) cJSON_AddItemToArray(a, cJSON_CreateNumber(x[i]));
    return a;
}

/* An accessor of count elements of `comps` floats (or uint32 indices when comps is 0), with min and max when
 * bounds is set (POSITION needs them). */
static int add_accessor(writer *w, const void *data, size_t count, int comps, int bounds)
{
    static const char *const types[] = { "SCALAR", "SCALAR", "VEC2", "VEC3", "VEC4" };
    const size_t elem = comps ? (size_t)comps * sizeof(float) : sizeof(uint32_t);
    const int view = add_view(w, data, count * elem, comps ? GL_ARRAY_BUFFER : GL_ELEMENT_ARRAY_BUFFER);
    cJSON *a = cJSON_CreateObject();
    cJSON_AddNumberToObject(a, "bufferView", view);
    cJSON_AddNumberToObject(a, "componentType", comps ? GL_FLOAT : GL_UNSIGNED_INT);
    cJSON_AddNumberToObject(a, "count", (double)count);
    cJSON_AddStringToObject(a, "type", types[comps]);
    if (bounds && comps) {
        float lo[4] = { INFINITY, INFINITY, INFINITY, INFINITY }, hi[4] = { -INFINITY, -INFINITY, -INFINITY, -INFINITY };
        const float *f = data;
        for (size_t i = 0; i < count; i++)
            for (int c = 0; c < comps; c++) { lo[c] = fminf(lo[c], f[i * comps + c]); hi[c] = fmaxf(hi[c], f[i * comps + c]); }
        cJSON_AddItemToObject(a, "min", num_array(lo, comps));
        cJSON_AddItemToObject(a, "max", num_array(hi, comps));
    }
    cJSON_AddItemToArray(w->accessors, a);
    return cJSON_GetArraySize(w->accessors) - 1;
}

/* An embedded PNG image of w x h pixels; its index, or -1 (err set). */
static int add_png(writer *w, const uint8_t *px, int width, int height, int channels, const char *what)
{
    unsigned char *png;
    size_t len;
    if (ms_png_encode(px, width, height, channels, what, &png, &len, w->err, w->errlen)) return -1;
    const int view = add_view(w, png, len, 0);
    free(png);
    cJSON *im = cJSON_CreateObject();
    cJSON_AddNumberToObject(im, "bufferView", view);
    cJSON_AddStringToObject(im, "mimeType", "image/png");
    cJSON_AddStringToObject(im, "name", what);
    cJSON_AddItemToArray(w->images, im);
    return cJSON_GetArraySize(w->images) - 1;
}

static int add_texture(writer *w, int image, int wrap_s, int wrap_t, int mag, int min)
{
    cJSON *s = cJSON_CreateObject();
    cJSON_AddNumberToObject(s, "magFilter", mag);
    cJSON_AddNumberToObject(s, "minFilter", min);
    cJSON_AddNumberToObject(s, "wrapS", wrap_s);
    cJSON_AddNumberToObject(s, "wrapT", wrap_t);
    cJSON_AddItemToArray(w->samplers, s);
    cJSON *t = cJSON_CreateObject();
    cJSON_AddNumberToObject(t, "sampler", cJSON_GetArraySize(w->samplers) - 1);
    cJSON_AddNumberToObject(t, "source", image);
    cJSON_AddItemToArray(w->textures, t);
    return cJSON_GetArraySize(w->textures) - 1;
}

static int gl_wrap(int32_t m) { return m == MS_WRAP_CLAMP ? GL_CLAMP_TO_EDGE : m == MS_WRAP_MIRROR ? GL_MIRRORED_REPEAT : GL_REPEAT; }

/* A textureInfo for scene texture `tex` sampled as `smp` at UV set `uv`, or NULL when it cannot be carried
 * (another UV set than 0, textures off, an unusable index): counted for one warning. -1 in *fail on an error. */
static cJSON *texture_info(writer *w, int32_t tex, int32_t uv, const ms_texture_sampling *smp, int *fail)
{
    if (w->opt.no_textures || tex < 0 || (size_t)tex >= w->sc->n_textures || !w->sc->textures[tex].rgba) return NULL;
    if (uv != 0) { w->dropped_uv_set++; return NULL; }
    if (w->image_of[tex] < 0) {
        const ms_texture *t = &w->sc->textures[tex];
        const size_t n = (size_t)t->width * t->height;
        int opaque = 1;
        for (size_t i = 0; i < n && opaque; i++) opaque = t->rgba[4 * i + 3] == 255;
        uint8_t *px = t->rgba, *rgb = NULL;
        if (opaque) {   /* RGB: a quarter smaller */
            rgb = malloc(3 * n);
            if (!rgb) { snprintf(w->err, w->errlen, "out of memory for texture %d", tex); *fail = -1; return NULL; }
            for (size_t i = 0; i < n; i++) memcpy(rgb + 3 * i, t->rgba + 4 * i, 3);
            px = rgb;
        }
        char name[48];
        snprintf(name, sizeof name, "texture %d", tex);
        w->image_of[tex] = add_png(w, px, t->width, t->height, opaque ? 3 : 4, name);
        free(rgb);
        if (w->image_of[tex] < 0) { *fail = -1; return NULL; }
    }
    if (smp->transformed) w->dropped_transform++;
    const int mipmaps = !smp->nearest;
    const int k = add_texture(w, w->image_of[tex], gl_wrap(smp->wrap_s), gl_wrap(smp->wrap_t), smp->nearest ? GL_NEAREST : GL_LINEAR,
                              mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_NEAREST);
    cJSON *ti = cJSON_CreateObject();
    cJSON_AddNumberToObject(ti, "index", k);
    return ti;
}

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }

/* The scene file's name of the shape (the light-shape table's: triangles and suns too). */
static const char *shape_name(ms_light_shape s)
{
    const ms_light_shape_ops *o = ms_light_shape_of(s);
    return o ? o->name : "rect";
}

/* Variants of a material: baked (TEXCOORD_1 and the lightmap), with TEXCOORD_0 (its textures). */
enum { VAR_BAKED = 1, VAR_UV0 = 2 };

/* The glTF material of scene material m (MS_NO_MATERIAL: the default grey) in variant var on lightmap page `page`,
 * named after the reason its triangles were not baked when they were not; -1 on error. */
static int material_for(writer *w, uint32_t m, int var, ms_unbaked why, uint32_t page)
{
    const size_t slot = (((m == MS_NO_MATERIAL ? 0 : (size_t)m + 1) * 4 + (size_t)var) * MS_UNBAKED_REASONS + (size_t)why) *
                            (size_t)w->pages + page;
    if (w->material_of[slot] >= 0) return w->material_of[slot];
    ms_material def;
    memset(&def, 0, sizeof def);
    def.base_color[0] = def.base_color[1] = def.base_color[2] = 0.8f;   /* microshadow's default albedo */
    def.base_color[3] = 1.0f;
    def.roughness = 1.0f;
    def.base_color_texture = def.alpha_texture = def.normal_texture = def.emissive_texture = def.mr_texture = -1;
    const ms_material *mt = m == MS_NO_MATERIAL ? &def : &w->sc->materials[m];
    cJSON *j = cJSON_CreateObject();
    char name[128], tail[64] = "", pg[24] = "";
    if (!(var & VAR_BAKED)) snprintf(tail, sizeof tail, " (not baked: %s)", ms_unbaked_name(why));
    if (w->pages > 1 && (var & VAR_BAKED)) snprintf(pg, sizeof pg, " (page %u)", page);   /* a copy per page */
    if (m == MS_NO_MATERIAL) snprintf(name, sizeof name, "default%s%s", tail, pg);
    else snprintf(name, sizeof name, "material %u%s%s", m, tail, pg);
    cJSON_AddStringToObject(j, "name", name);
    cJSON *pbr = cJSON_AddObjectToObject(j, "pbrMetallicRoughness");
    float bc[4];
    for (int c = 0; c < 4; c++) bc[c] = clamp01(mt->base_color[c]);
    cJSON_AddItemToObject(pbr, "baseColorFactor", num_array(bc, 4));
    cJSON_AddNumberToObject(pbr, "metallicFactor", clamp01(mt->metallic));
    cJSON_AddNumberToObject(pbr, "roughnessFactor", clamp01(mt->roughness));
    int fail = 0;
    if (var & VAR_UV0) {
        cJSON *t = texture_info(w, mt->base_color_texture, mt->base_color_uv, &mt->base_color_sampling, &fail);
        if (t) cJSON_AddItemToObject(pbr, "baseColorTexture", t);
        if (mt->mr_map && !fail && (t = texture_info(w, mt->mr_texture, mt->mr_uv, &mt->mr_sampling, &fail)))
            cJSON_AddItemToObject(pbr, "metallicRoughnessTexture", t);
        if (mt->normal_map && !fail && (t = texture_info(w, mt->normal_texture, mt->normal_uv, &mt->normal_sampling, &fail))) {
            cJSON_AddNumberToObject(t, "scale", mt->normal_scale);
            cJSON_AddItemToObject(j, "normalTexture", t);
        }
        if (mt->emissive_map && !fail && (t = texture_info(w, mt->emissive_texture, mt->emissive_uv, &mt->emissive_sampling, &fail)))
            cJSON_AddItemToObject(j, "emissiveTexture", t);
    }
    if (fail) { cJSON_Delete(j); return -1; }
    const float emax = fmaxf(mt->emissive[0], fmaxf(mt->emissive[1], mt->emissive[2]));
    if (emax > 0.0f && isfinite(emax)) {
        /* core glTF caps the factor at 1: the rest goes to KHR_materials_emissive_strength */
        const float s = emax > 1.0f ? emax : 1.0f;
        const float e[3] = { mt->emissive[0] / s, mt->emissive[1] / s, mt->emissive[2] / s };
        cJSON_AddItemToObject(j, "emissiveFactor", num_array(e, 3));
        if (s > 1.0f) {
            cJSON *ext = cJSON_AddObjectToObject(j, "extensions");
            cJSON_AddNumberToObject(cJSON_AddObjectToObject(ext, "KHR_materials_emissive_strength"), "emissiveStrength", s);
            w->used_emissive_strength = 1;
        }
    }
    if (mt->alpha_mode != MS_ALPHA_OPAQUE) {
        cJSON_AddStringToObject(j, "alphaMode", "MASK");
        cJSON_AddNumberToObject(j, "alphaCutoff", mt->alpha_cutoff);
    }
    if (var & VAR_BAKED) {
        cJSON *ext = cJSON_GetObjectItem(j, "extensions");
        if (!ext) ext = cJSON_AddObjectToObject(j, "extensions");
        cJSON *lm = cJSON_AddObjectToObject(ext, "MOZ_lightmap");
        cJSON_AddNumberToObject(lm, "index", w->lightmap_tex[page]);
        cJSON_AddNumberToObject(lm, "texCoord", 1);
        cJSON_AddNumberToObject(lm, "intensity", w->intensity);
        if (w->shadowmask_tex[page] >= 0) {
            cJSON *sm = cJSON_AddObjectToObject(cJSON_AddObjectToObject(j, "extras"), "shadowmask");
            cJSON_AddNumberToObject(sm, "index", w->shadowmask_tex[page]);
            cJSON_AddNumberToObject(sm, "texCoord", 1);
            cJSON *ch = cJSON_AddArrayToObject(sm, "channels");
            size_t nl;
            const ms_light *L = ms_scene_lights(w->sc, &nl);
            for (size_t l = 0; l < nl && l < 4; l++) {
                cJSON *c = cJSON_CreateObject();
                const char cn[2] = { "RGBA"[l], 0 };
                cJSON_AddStringToObject(c, "channel", cn);
                cJSON_AddNumberToObject(c, "light", (double)l);
                cJSON_AddStringToObject(c, "shape", shape_name(L[l].shape));
                cJSON_AddItemToArray(ch, c);
            }
        }
    }
    cJSON_AddItemToArray(w->materials, j);
    return w->material_of[slot] = cJSON_GetArraySize(w->materials) - 1;
}

/* The lightmap and shadowmask images (before any material references them). */
static int add_maps(writer *w)
{
    const ms_frame *f = &w->lm->frame;
    const size_t np = (size_t)f->width * f->height;
    const size_t nl = f->n_lights > 1 ? (size_t)f->n_lights : 1;
    double imax = 0.0;
    for (size_t i = 0; i < np; i++)
        if (f->vis[i] >= 0.0f)
            for (int c = 0; c < 3; c++) imax = fmax(imax, f->rgb[3 * i + c]);
    w->intensity = imax > 0.0 ? imax : 1.0;
    const size_t nmask = w->opt.no_shadowmask ? 0 : nl;
    /* one lightmap and one shadowmask image per page (the frame's rows [p size, (p+1) size)) */
    const size_t pp = (size_t)f->width * f->width;
    uint8_t *px = malloc(4 * pp);
    if (!px) { snprintf(w->err, w->errlen, "out of memory for the lightmap's image"); return -1; }
    for (int p = 0; p < w->pages; p++) {
        const size_t o = (size_t)p * pp;
        for (size_t i = 0; i < pp; i++)
            for (int c = 0; c < 3; c++)   /* linear; the nearest of the 256 steps */
                px[3 * i + c] = f->vis[o + i] >= 0.0f ? (uint8_t)lrint(clamp01((float)(f->rgb[3 * (o + i) + c] / w->intensity)) * 255.0) : 0;
        int im = add_png(w, px, f->width, f->width, 3, "lightmap");
        if (im < 0) { free(px); return -1; }
        /* no mipmaps: a minified lightmap would average across chart borders into the padding */
        w->lightmap_tex[p] = add_texture(w, im, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE, GL_LINEAR, GL_LINEAR);
        w->shadowmask_tex[p] = -1;
        if (!nmask) continue;
        for (size_t i = 0; i < pp; i++)
            for (size_t c = 0; c < 4; c++) {
                const float s = c < nl ? f->shadow[c * np + o + i] : -1.0f;
                px[4 * i + c] = c < nl ? (s >= 0.0f ? (uint8_t)lrint(clamp01(s) * 255.0f) : 0) : (c == 3 ? 255 : 0);
            }
        im = add_png(w, px, f->width, f->width, 4, "shadowmask");
        if (im < 0) { free(px); return -1; }
        w->shadowmask_tex[p] = add_texture(w, im, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE, GL_LINEAR, GL_LINEAR);
    }
    if (nmask && nl > 4) ms_warn("the glTF's shadowmask holds lights 0-3 only: lights 4-%zu are in the EXR (-o) alone", nl - 1);
    free(px);
    return 0;
}

/* A triangle's group: its object (ms_scene.tri_object, else its mesh), material and variant. */
typedef struct tri_key {
    uint32_t mesh, material, var, why, tri, page;   /* why: ms_unbaked, for the triangles not baked */
} tri_key;

static int cmp_key(const void *pa, const void *pb)
{
    const tri_key *a = pa, *b = pb;
    if (a->mesh != b->mesh) return a->mesh < b->mesh ? -1 : 1;
    if (a->material != b->material) return a->material < b->material ? -1 : 1;
    if (a->var != b->var) return a->var < b->var ? -1 : 1;
    if (a->why != b->why) return a->why < b->why ? -1 : 1;
    if (a->page != b->page) return a->page < b->page ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri);
}

/* One vertex: position, normal, UV 0, UV 1, tangent (zero where the primitive has none). */
typedef struct vert { float p[3], n[3], uv0[2], uv1[2], t[4]; } vert;

static uint64_t hash_vert(const vert *v)
{
    const unsigned char *b = (const unsigned char *)v;
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < sizeof *v; i++) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

static int all_finite(const float *x, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* The unit geometric normal of triangle t into n; 0 when it has no area. */
static int face_normal(const float *t, float n[3])
{
    const double e1[3] = { t[3] - t[0], t[4] - t[1], t[5] - t[2] }, e2[3] = { t[6] - t[0], t[7] - t[1], t[8] - t[2] };
    const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0] };
    const double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (!(len > 0.0) || !isfinite(len)) return 0;
    for (int d = 0; d < 3; d++) n[d] = (float)(c[d] / len);
    return 1;
}

/* The TANGENT of corner c of triangle t (unit normal n as written): the scene's (the asset's, or MikkTSpace's
 * made at load, as the renderer reads them), else the triangle's UV frame the renderer falls back on
 * (ms_uv_tangent); made orthogonal to n and unit, w = +-1 (the validator's rules). */
static void vertex_tangent(const ms_scene *sc, size_t t, int c, int32_t set, const float n[3], float out[4])
{
    const float *tg = sc->tri_tangent ? sc->tri_tangent + 12 * t : NULL;
    for (int k = 0; tg && k < 12; k++)
        if (!isfinite(tg[k])) tg = NULL;
    float T[3] = { 0, 0, 0 }, w = 1.0f;
    if (tg) {
        memcpy(T, tg + 4 * c, sizeof T);
        w = tg[4 * c + 3] < 0.0f ? -1.0f : 1.0f;
    } else if (set < 0 || set >= MS_MAX_UV_SETS || !sc->tri_uv[set] || !ms_uv_tangent(sc, t, set, n, T, &w))
        memset(T, 0, sizeof T);
    double d = (double)T[0] * n[0] + (double)T[1] * n[1] + (double)T[2] * n[2], o[3], len = 0.0;
    for (int k = 0; k < 3; k++) { o[k] = T[k] - d * n[k]; len += o[k] * o[k]; }
    len = sqrt(len);
    if (!(len > 1e-12) || !isfinite(len)) {   /* no frame: any unit vector orthogonal to n */
        const int a = fabsf(n[0]) < 0.9f ? 0 : 1;
        const double e[3] = { a == 0, a == 1, 0 };
        d = e[0] * n[0] + e[1] * n[1];
        len = 0.0;
        for (int k = 0; k < 3; k++) { o[k] = e[k] - d * n[k]; len += o[k] * o[k]; }
        len = sqrt(len);
    }
    for (int k = 0; k < 3; k++) out[k] = (float)(o[k] / len);
    out[3] = w;
}

/* One primitive of the triangles keys[0..n) (one group), welded; its JSON, or NULL on error. */
static cJSON *add_primitive(writer *w, const tri_key *keys, size_t n)
{
    const ms_scene *sc = w->sc;
    const int var = (int)keys[0].var;
    vert *vs = malloc(3 * n * sizeof *vs);
    uint32_t *idx = malloc(3 * n * sizeof *idx);
    size_t cap = 16;
    while (cap < 6 * n) cap *= 2;
    uint32_t *slot = malloc(cap * sizeof *slot);
    if (!vs || !idx || !slot) {
        free(vs); free(idx); free(slot);
        snprintf(w->err, w->errlen, "out of memory for a primitive of %zu triangles", n);
        return NULL;
    }
    memset(slot, 0xff, cap * sizeof *slot);
    /* The material first: a normal texture carried into the file needs TANGENT on the vertices. */
    const int mat = material_for(w, keys[0].material, var, (ms_unbaked)keys[0].why, keys[0].page);
    if (mat < 0) { free(vs); free(idx); free(slot); return NULL; }
    const uint32_t sm = keys[0].material;
    const int tangents = cJSON_GetObjectItem(cJSON_GetArrayItem(w->materials, mat), "normalTexture") != NULL;
    const int32_t tset = sm < sc->n_materials ? sc->materials[sm].normal_uv : 0;
    size_t nv = 0;
    for (size_t k = 0; k < n; k++) {
        const size_t t = keys[k].tri;
        const float *tri = sc->tri + 9 * t;
        float fn[3];
        face_normal(tri, fn);   /* zero-area triangles were left out before */
        for (int c = 0; c < 3; c++) {
            vert v;
            memset(&v, 0, sizeof v);
            memcpy(v.p, tri + 3 * c, sizeof v.p);
            const float *sn = sc->tri_normal ? sc->tri_normal + 9 * t + 3 * c : NULL;
            const double sl = sn && all_finite(sn, 3) ? sqrt((double)sn[0] * sn[0] + (double)sn[1] * sn[1] + (double)sn[2] * sn[2]) : 0.0;
            for (int d = 0; d < 3; d++) v.n[d] = sl > 0.0 ? (float)(sn[d] / sl) : fn[d];
            if (var & VAR_UV0) memcpy(v.uv0, sc->tri_uv[0] + 6 * t + 2 * c, sizeof v.uv0);
            if (var & VAR_BAKED) memcpy(v.uv1, w->lm->uv + 6 * t + 2 * c, sizeof v.uv1);
            if (tangents) vertex_tangent(sc, t, c, tset, v.n, v.t);
            size_t h = (size_t)(hash_vert(&v) & (cap - 1));
            while (slot[h] != UINT32_MAX && memcmp(&vs[slot[h]], &v, sizeof v)) h = (h + 1) & (cap - 1);
            if (slot[h] == UINT32_MAX) { slot[h] = (uint32_t)nv; vs[nv++] = v; }
            idx[3 * k + (size_t)c] = slot[h];
        }
    }
    free(slot);
    /* attribute arrays out of the interleaved vertices */
    float *a = malloc(nv * 4 * sizeof *a);
    if (!a) { free(vs); free(idx); snprintf(w->err, w->errlen, "out of memory for a primitive"); return NULL; }
    cJSON *prim = cJSON_CreateObject(), *attr = cJSON_AddObjectToObject(prim, "attributes");
    for (size_t i = 0; i < nv; i++) memcpy(a + 3 * i, vs[i].p, 3 * sizeof(float));
    cJSON_AddNumberToObject(attr, "POSITION", add_accessor(w, a, nv, 3, 1));
    for (size_t i = 0; i < nv; i++) memcpy(a + 3 * i, vs[i].n, 3 * sizeof(float));
    cJSON_AddNumberToObject(attr, "NORMAL", add_accessor(w, a, nv, 3, 0));
    if (tangents) {
        for (size_t i = 0; i < nv; i++) memcpy(a + 4 * i, vs[i].t, 4 * sizeof(float));
        cJSON_AddNumberToObject(attr, "TANGENT", add_accessor(w, a, nv, 4, 0));
    }
    if (var & VAR_UV0) {
        for (size_t i = 0; i < nv; i++) memcpy(a + 2 * i, vs[i].uv0, 2 * sizeof(float));
        cJSON_AddNumberToObject(attr, "TEXCOORD_0", add_accessor(w, a, nv, 2, 0));
    }
    if (var & VAR_BAKED) {
        /* glTF numbers texture coordinates densely: the lightmap's set is TEXCOORD_1 only beside a TEXCOORD_0 */
        if (!(var & VAR_UV0)) {
            for (size_t i = 0; i < nv; i++) memcpy(a + 2 * i, vs[i].uv1, 2 * sizeof(float));
            cJSON_AddNumberToObject(attr, "TEXCOORD_0", add_accessor(w, a, nv, 2, 0));
        }
        for (size_t i = 0; i < nv; i++) memcpy(a + 2 * i, vs[i].uv1, 2 * sizeof(float));
        cJSON_AddNumberToObject(attr, "TEXCOORD_1", add_accessor(w, a, nv, 2, 0));
    }
    cJSON_AddNumberToObject(prim, "indices", add_accessor(w, idx, 3 * n, 0, 0));
    free(a);
    free(vs);
    free(idx);
    cJSON_AddNumberToObject(prim, "material", mat);
    if (var & VAR_BAKED) ms_bake_gltf_lightmap_extras(prim, w->lm, keys[0].mesh, keys[0].page);
    cJSON_AddNumberToObject(prim, "mode", 4);
    if (!(var & VAR_BAKED)) {   /* glTF primitives have no name: extras say why they carry no lightmap */
        cJSON *ex = cJSON_AddObjectToObject(prim, "extras");
        char why[64];
        snprintf(why, sizeof why, "not baked: %s", ms_unbaked_name((ms_unbaked)keys[0].why));
        cJSON_AddStringToObject(ex, "name", why);
        cJSON_AddNumberToObject(ex, "triangles", (double)n);
    }
    return prim;
}

/* The scene's extras.microshadow (viewer/index.html: three.js puts them in gltf.scene.userData): the scene's
 * lights and camera (bake_gltf_lights.h), and the exposures microshadow's frame of the scene's camera picks by itself
 * (frame_shade.h), standard and diffuse, so that a viewer shows the bake as the frame shows the scene by default.
 * The exposures are left out, with a warning, if they cannot be computed: the glb is still whole. */
static void add_scene_extras(const ms_scene *sc, cJSON *scene0)
{
    cJSON *ms = cJSON_AddObjectToObject(cJSON_AddObjectToObject(scene0, "extras"), "microshadow");
    ms_bake_gltf_lights(ms, sc);
    ms_bake_gltf_camera(ms, sc);
    float e[2];
    char why[256] = "";
    for (int k = 0; k < 2; k++)
        if (ms_frame_auto_exposure(sc, k ? MS_SHADING_DIFFUSE : MS_SHADING_STANDARD, 0, &e[k], why, sizeof why)) {
            ms_warn("the glTF carries no exposure for its viewer: %s", why);
            return;
        }
    cJSON_AddNumberToObject(ms, "exposure", e[0]);
    cJSON_AddNumberToObject(ms, "exposure_diffuse", e[1]);
}

/* The triangles to write as keys, sorted by mesh, material, variant and page; zero-area ones left out (with a
 * warning). Returns how many. */
static size_t sorted_keys(const ms_scene *sc, const ms_lightmap *lm, tri_key *keys)
{
    const size_t n = sc->n_tris;
    size_t m = 0, flat = 0;
    for (size_t t = 0; t < n; t++) {
        float fn[3];
        if (!face_normal(sc->tri + 9 * t, fn)) { flat++; continue; }
        int var = all_finite(lm->uv + 6 * t, 6) ? VAR_BAKED : 0;
        if (sc->tri_uv[0] && all_finite(sc->tri_uv[0] + 6 * t, 6)) var |= VAR_UV0;
        keys[m].mesh = sc->tri_object ? sc->tri_object[t] : sc->tri_mesh ? sc->tri_mesh[t] : 0;
        keys[m].material = sc->tri_material && sc->tri_material[t] < sc->n_materials ? sc->tri_material[t] : MS_NO_MATERIAL;
        keys[m].var = (uint32_t)var;
        keys[m].why = var & VAR_BAKED ? MS_BAKED : (uint32_t)ms_bake_tri_state(sc, lm->uv, lm->frame.width, t);
        keys[m].page = (var & VAR_BAKED) && lm->page && lm->pages > 1 ? lm->page[t] : 0;
        keys[m++].tri = (uint32_t)t;
    }
    if (flat) ms_warn("%zu triangles without area (no normal) left out of the glTF", flat);
    qsort(keys, m, sizeof *keys, cmp_key);
    return m;
}

/* The node tree: a root carrying the scene's origin, one node and mesh per object, one primitive per run of keys
 * sharing material, variant and page. MS_OK, or the failure of a primitive (its message in w->err). */
static ms_status add_meshes(writer *w, const tri_key *keys, size_t m)
{
    const ms_scene *sc = w->sc;
    ms_status st = MS_OK;
    cJSON *root_node = cJSON_CreateObject();
    cJSON_AddStringToObject(root_node, "name", "microshadow bake");
    if (sc->origin[0] != 0.0 || sc->origin[1] != 0.0 || sc->origin[2] != 0.0) {
        cJSON *tr = cJSON_AddArrayToObject(root_node, "translation");
        for (int d = 0; d < 3; d++) cJSON_AddItemToArray(tr, cJSON_CreateNumber(sc->origin[d]));
    }
    cJSON *children = cJSON_AddArrayToObject(root_node, "children");
    cJSON_AddItemToArray(w->nodes, root_node);
    for (size_t a = 0; a < m && !st;) {
        size_t b = a;
        while (b < m && keys[b].mesh == keys[a].mesh) b++;
        cJSON *mesh = cJSON_CreateObject();
        char name[64];
        if (sc->tri_object && sc->tri_mesh)
            snprintf(name, sizeof name, "object %u (scene mesh %u)", keys[a].mesh, sc->tri_mesh[keys[a].tri]);
        else snprintf(name, sizeof name, "mesh %u", keys[a].mesh);
        cJSON_AddStringToObject(mesh, "name", name);
        cJSON *prims = cJSON_AddArrayToObject(mesh, "primitives");
        cJSON_AddItemToArray(w->meshes, mesh);
        for (size_t p = a; p < b && !st;) {
            size_t q = p;
            while (q < b && keys[q].material == keys[p].material && keys[q].var == keys[p].var && keys[q].page == keys[p].page) q++;
            cJSON *prim = add_primitive(w, keys + p, q - p);
            if (!prim) st = w->bin.oom ? MS_ERR_NO_MEMORY : MS_ERR_INVALID;
            else cJSON_AddItemToArray(prims, prim);
            p = q;
        }
        cJSON *node = cJSON_CreateObject();
        cJSON_AddStringToObject(node, "name", name);
        cJSON_AddNumberToObject(node, "mesh", cJSON_GetArraySize(w->meshes) - 1);
        cJSON_AddItemToArray(w->nodes, node);
        cJSON_AddItemToArray(children, cJSON_CreateNumber(cJSON_GetArraySize(w->nodes) - 1));
        a = b;
    }
    return st;
}

/* The glb of w's JSON and binary chunk: a malloc'ed buffer *glb of *len bytes. MS_OK, or a status with a message. */
static ms_status glb_bytes(const writer *w, unsigned char **glb, size_t *len, char *err, size_t errlen)
{
    char *json = cJSON_PrintUnformatted(w->root);
    if (!json) { snprintf(err, errlen, "out of memory printing the glTF's JSON"); return MS_ERR_NO_MEMORY; }
    const size_t jn = strlen(json), jpad = (jn + 3) & ~(size_t)3;
    const size_t total = 12 + 8 + jpad + 8 + w->bin.n;
    if (total > UINT32_MAX) {
        snprintf(err, errlen, "the glTF would be %zu bytes, more than a .glb holds (4 GiB)", total);
        free(json);
        return MS_ERR_INVALID;
    }
    unsigned char *out = malloc(total);
    if (!out) { free(json); snprintf(err, errlen, "out of memory for a %zu-byte glTF", total); return MS_ERR_NO_MEMORY; }
    const uint32_t head[5] = { 0x46546C67u /* glTF */, 2, (uint32_t)total, (uint32_t)jpad, 0x4E4F534Au /* JSON */ };
    memcpy(out, head, sizeof head);   /* little-endian, as x86 and the glb are */
    memcpy(out + 20, json, jn);
    memset(out + 20 + jn, ' ', jpad - jn);
    const uint32_t bhead[2] = { (uint32_t)w->bin.n, 0x004E4942u /* BIN */ };
    memcpy(out + 20 + jpad, bhead, sizeof bhead);
    memcpy(out + 28 + jpad, w->bin.p, w->bin.n);
    free(json);
    *glb = out;
    *len = total;
    return MS_OK;
}

ms_status ms_bake_gltf_abi(const ms_abi *abi, const ms_scene *sc, const ms_lightmap *lm, const ms_bake_gltf_options *opt,
                           unsigned char **glb, size_t *len, char *err, size_t errlen)
{
    const ms_status ast = ms_abi_check(abi, "ms_bake_gltf", err, errlen);
    if (ast) return ast;
    ms_bake_gltf_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, bake_gltf_options), &own, sizeof own);
    if (glb) *glb = NULL;
    if (len) *len = 0;
    if (!sc || !lm || !glb || !len) { snprintf(err, errlen, "ms_bake_gltf: NULL argument"); return MS_ERR_INVALID; }
    if (!sc->tri || !lm->uv || lm->n_tris != sc->n_tris || !lm->frame.rgb || !lm->frame.vis || !lm->frame.shadow) {
        snprintf(err, errlen, "ms_bake_gltf: the lightmap is not a bake of this scene (%zu triangles, the lightmap's %zu)",
                 sc->n_tris, lm->n_tris);
        return MS_ERR_INVALID;
    }
    size_t nl;
    ms_scene_lights(sc, &nl);
    if ((size_t)(lm->frame.n_lights > 1 ? lm->frame.n_lights : 1) != (nl ? nl : 1)) {
        snprintf(err, errlen, "ms_bake_gltf: the lightmap has %d lights, the scene %zu", lm->frame.n_lights, nl);
        return MS_ERR_INVALID;
    }
    writer w;
    memset(&w, 0, sizeof w);
    w.sc = sc;
    w.lm = lm;
    if (opt) w.opt = *opt;
    w.err = err;
    w.errlen = errlen;
    ms_status st = MS_OK;
    const size_t n = sc->n_tris;
    w.image_of = malloc((sc->n_textures ? sc->n_textures : 1) * sizeof *w.image_of);
    w.pages = lm->pages > 1 ? lm->pages : 1;
    w.material_of = malloc((sc->n_materials + 1) * 4 * MS_UNBAKED_REASONS * (size_t)w.pages * sizeof *w.material_of);
    w.lightmap_tex = malloc((size_t)w.pages * sizeof *w.lightmap_tex);
    w.shadowmask_tex = malloc((size_t)w.pages * sizeof *w.shadowmask_tex);
    tri_key *keys = malloc((n ? n : 1) * sizeof *keys);
    w.root = cJSON_CreateObject();
    if (!w.image_of || !w.material_of || !w.lightmap_tex || !w.shadowmask_tex || !keys || !w.root) {
        snprintf(err, errlen, "out of memory for the glTF of %zu triangles", n);
        st = MS_ERR_NO_MEMORY;
        goto done;
    }
    for (size_t i = 0; i < sc->n_textures; i++) w.image_of[i] = -1;
    for (size_t i = 0; i < (sc->n_materials + 1) * 4 * MS_UNBAKED_REASONS * (size_t)w.pages; i++) w.material_of[i] = -1;

    cJSON *asset = cJSON_AddObjectToObject(w.root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    char gen[64];
    snprintf(gen, sizeof gen, "microshadow %s bake", ms_version(NULL, NULL, NULL));
    cJSON_AddStringToObject(asset, "generator", gen);
    cJSON *used = cJSON_AddArrayToObject(w.root, "extensionsUsed");
    cJSON_AddItemToArray(used, cJSON_CreateString("MOZ_lightmap"));
    cJSON_AddNumberToObject(w.root, "scene", 0);
    cJSON *scenes = cJSON_AddArrayToObject(w.root, "scenes");
    w.nodes = cJSON_AddArrayToObject(w.root, "nodes");
    w.meshes = cJSON_AddArrayToObject(w.root, "meshes");
    w.materials = cJSON_AddArrayToObject(w.root, "materials");
    w.textures = cJSON_AddArrayToObject(w.root, "textures");
    w.samplers = cJSON_AddArrayToObject(w.root, "samplers");
    w.images = cJSON_AddArrayToObject(w.root, "images");
    w.accessors = cJSON_AddArrayToObject(w.root, "accessors");
    w.views = cJSON_AddArrayToObject(w.root, "bufferViews");
    cJSON *buffers = cJSON_AddArrayToObject(w.root, "buffers");
    if (add_maps(&w)) { st = w.bin.oom ? MS_ERR_NO_MEMORY : MS_ERR_INVALID; goto done; }

    const size_t m = sorted_keys(sc, lm, keys);
    st = add_meshes(&w, keys, m);
    if (st) goto done;
    if (w.dropped_uv_set) ms_warn("%d material textures on a UV set other than 0 left out of the glTF", w.dropped_uv_set);
    if (w.dropped_transform) ms_warn("%d material textures carried into the glTF without their KHR_texture_transform", w.dropped_transform);
    if (w.used_emissive_strength) cJSON_AddItemToArray(used, cJSON_CreateString("KHR_materials_emissive_strength"));
    cJSON *scene0 = cJSON_CreateObject();
    cJSON_AddItemToArray(cJSON_AddArrayToObject(scene0, "nodes"), cJSON_CreateNumber(0));
    add_scene_extras(sc, scene0);
    cJSON_AddItemToArray(scenes, scene0);
    if (w.bin.oom) { snprintf(err, errlen, "out of memory for the glTF's binary chunk"); st = MS_ERR_NO_MEMORY; goto done; }
    bin_put(&w.bin, NULL, 0);   /* pad to 4 */
    cJSON *buf0 = cJSON_CreateObject();
    cJSON_AddNumberToObject(buf0, "byteLength", (double)w.bin.n);
    cJSON_AddItemToArray(buffers, buf0);
    st = glb_bytes(&w, glb, len, err, errlen);
done:
    cJSON_Delete(w.root);
    free(w.bin.p);
    free(w.image_of);
    free(w.material_of);
    free(w.lightmap_tex);
    free(w.shadowmask_tex);
    free(keys);
    return st;
}

ms_status ms_bake_write_gltf_abi(const ms_abi *abi, const ms_scene *sc, const ms_lightmap *lm,
                                 const ms_bake_gltf_options *opt, const char *path, char *err, size_t errlen)
{
    const ms_status ast = ms_abi_check(abi, "ms_bake_write_gltf", err, errlen);
    if (ast) return ast;
    ms_bake_gltf_options own;
    opt = ms_abi_options(opt, MS_ABI_SIZE(abi, bake_gltf_options), &own, sizeof own);
    static const char *const glb_suffix[] = { ".glb", NULL };
    ms_output o = { "glTF", path ? path : "", NULL, glb_suffix, NULL, 0 };
    if (ms_outputs_check(&o, 1, err, errlen)) return MS_ERR_IO;
    unsigned char *glb;
    size_t len;
    ms_status st = ms_bake_gltf(sc, lm, opt, &glb, &len, err, errlen);
    if (st) return st;
    o.bytes = glb;
    o.n_bytes = len;
    st = ms_outputs_write(&lm->frame, &o, 1, err, errlen) ? MS_ERR_IO : MS_OK;
    free(glb);
    return st;
}
