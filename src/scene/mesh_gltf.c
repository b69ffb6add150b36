/* glTF 2.0 (.gltf, .glb) through cgltf rather than assimp: cgltf is small, fuzzed upstream and here,
 * and lets us bound its memory (an allocator with a budget), read external buffers ourselves
 * (regular files only) and check every accessor we read against the bytes behind it. */
#include "scene_internal.h"
#include "microshadow.h"
#include "cgltf.h"
#include "gltf_decode.h"
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct gltf_ctx {
    size_t used, limit;        /* bytes cgltf allocated, and its budget (a multiple of the input) */
    size_t input;              /* bytes of input: the file and the external buffers read so far */
    char why[512];             /* the reason an external buffer could not be read */
} gltf_ctx;

/* cgltf's parse structures are up to ~200 times the JSON they come from ("{}" is a whole node). */
#define GLTF_BUDGET_PER_BYTE 256
#define GLTF_BUDGET_BASE ((size_t)16 << 20)

static void *budget_alloc(void *user, cgltf_size size)
{
    gltf_ctx *g = user;
    if (size > g->limit - g->used) return NULL;
    void *p = malloc(size ? size : 1);
    if (p) g->used += size;
    return p;
}

static void budget_free(void *user, void *ptr) { (void)user; free(ptr); }

static cgltf_result read_buffer_file(const struct cgltf_memory_options *mo, const struct cgltf_file_options *fo,
                                     const char *path, cgltf_size *size, void **data)
{
    (void)mo;
    gltf_ctx *g = fo->user_data;
    char *buf;
    size_t len;
    if (ms_read_input(path, MS_MAX_MESH_BYTES, MS_INPUT_MESH, &buf, &len, g->why, sizeof g->why))
        return cgltf_result_file_not_found;
    if (len < *size) {
        snprintf(g->why, sizeof g->why, "%.400s: holds %zu bytes, fewer than the %zu the glTF declares", path, len, (size_t)*size);
        free(buf);
        return cgltf_result_data_too_short;
    }
    g->input += len;
    g->limit += len;
    *data = buf;
    return cgltf_result_success;
}

static void release_buffer_file(const struct cgltf_memory_options *mo, const struct cgltf_file_options *fo, void *data)
{
    (void)mo; (void)fo;
    free(data);
}

static const char *result_text(cgltf_result r)
{
    switch (r) {
    case cgltf_result_data_too_short: return "the data is shorter than it declares";
    case cgltf_result_unknown_format: return "not a glTF 2.0 file";
    case cgltf_result_invalid_json: return "malformed JSON";
    case cgltf_result_invalid_gltf: return "invalid glTF (a reference out of range, a node with two parents or a cycle, or a missing required property)";
    case cgltf_result_file_not_found: return "a buffer file cannot be read";
    case cgltf_result_io_error: return "a buffer cannot be read";
    case cgltf_result_out_of_memory: return "it needs more memory than its size allows";
    case cgltf_result_legacy_gltf: return "glTF 1.0 is not supported";
    default: return "cannot be read";
    }
}

/* The accessor can be read element by element without leaving its buffer's data (a decoded or dense view's
 * data is exactly its size; ms_gltf_sparse_ok checks a sparse accessor's own parts). */
static int accessor_ok(const cgltf_accessor *a, char *why, size_t n)
{
    if (a->count == 0) { snprintf(why, n, "an accessor has no elements"); return 0; }
    const cgltf_buffer_view *v = a->buffer_view;
    if (!v) return 1;   /* no view: all zeros, read without touching memory */
    const unsigned char *base;
    if (v->data) {
        base = v->data;
    } else {
        if (v->has_meshopt_compression) { snprintf(why, n, "a meshopt-compressed buffer view was not decoded"); return 0; }
        if (!v->buffer || !v->buffer->data) { snprintf(why, n, "an accessor's buffer has no data"); return 0; }
        if (!ms_fits(v->offset, v->size, v->buffer->size)) { snprintf(why, n, "a buffer view exceeds its buffer"); return 0; }
        base = (const unsigned char *)v->buffer->data + v->offset;
    }
    size_t elem = cgltf_calc_size(a->type, a->component_type);
    if (elem == 0 || (a->stride < elem && a->count > 1)) { snprintf(why, n, "an accessor has an invalid stride"); return 0; }
    /* cgltf reads components through typed pointers: they must be aligned (glTF requires it too). */
    size_t comp = cgltf_component_size(a->component_type);
    if (comp == 0 || ((uintptr_t)base + a->offset) % comp || a->stride % comp) {
        snprintf(why, n, "an accessor is not aligned to its component size");
        return 0;
    }
    if (a->count - 1 > (SIZE_MAX - elem) / (a->stride ? a->stride : 1) ||
        !ms_fits(a->offset, (a->count - 1) * a->stride + elem, v->size)) {
        snprintf(why, n, "an accessor exceeds its buffer view");
        return 0;
    }
    return 1;
}

static void mat4_mul(float r[16], const float a[16], const float b[16])   /* column-major, r = a b */
{
    float t[16];
    for (int c = 0; c < 4; c++)
        for (int i = 0; i < 4; i++) {
            float s = 0;
            for (int k = 0; k < 4; k++) s += a[k * 4 + i] * b[c * 4 + k];
            t[c * 4 + i] = s;
        }
    memcpy(r, t, sizeof t);
}

static int emit_primitive(const cgltf_data *d, const long *mat_of, const cgltf_primitive *pr, const float m[16],
                          ms_tri_soup *soup, size_t *added, size_t max_tris, const char *path, char *err, size_t errlen)
{
    if (pr->type != cgltf_primitive_type_triangles && pr->type != cgltf_primitive_type_triangle_strip &&
        pr->type != cgltf_primitive_type_triangle_fan)
        return 0;   /* points and lines cast no shadow */
    char why[128];
    const cgltf_accessor *pos = NULL;
    for (size_t i = 0; i < pr->attributes_count; i++)
        if (pr->attributes[i].type == cgltf_attribute_type_position && pr->attributes[i].index == 0) pos = pr->attributes[i].data;
    if (!pos) { snprintf(err, errlen, "%s: a triangle primitive has no POSITION", path); return -1; }
    /* TEXCOORD_s is UV set s (baking); an unusable one is ignored like an absent one. */
    const cgltf_accessor *tc[MS_SOUP_UV_SETS] = { NULL };
    for (size_t i = 0; i < pr->attributes_count; i++) {
        const cgltf_attribute *a = &pr->attributes[i];
        if (a->type == cgltf_attribute_type_texcoord && a->index >= 0 && a->index < MS_SOUP_UV_SETS && a->data &&
            a->data->type == cgltf_type_vec2 && a->data->count == pos->count && accessor_ok(a->data, why, sizeof why))
            tc[a->index] = a->data;
    }
    /* NORMAL: shading normals (an unusable accessor is ignored like an absent one: the geometric normal
     * shades), carried to world space by the cofactor matrix of m (the inverse transpose up to scale). */
    const cgltf_accessor *nrm = NULL;
    for (size_t i = 0; i < pr->attributes_count; i++) {
        const cgltf_attribute *a = &pr->attributes[i];
        if (a->type == cgltf_attribute_type_normal && a->index == 0 && a->data && a->data->type == cgltf_type_vec3 &&
            a->data->count == pos->count && accessor_ok(a->data, why, sizeof why))
            nrm = a->data;
    }
    float cof[9];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[3 * r + c] = m[4 * c1 + r1] * m[4 * c2 + r2] - m[4 * c2 + r1] * m[4 * c1 + r2];
        }
    const uint32_t material = pr->material && mat_of ? (uint32_t)mat_of[pr->material - d->materials] : MS_NO_MATERIAL;
    if (pos->type != cgltf_type_vec3) { snprintf(err, errlen, "%s: POSITION is not a VEC3 accessor", path); return -1; }
    if (!accessor_ok(pos, why, sizeof why)) { snprintf(err, errlen, "%s: %s", path, why); return -1; }
    const cgltf_accessor *ix = pr->indices;
    if (ix) {
        if (ix->type != cgltf_type_scalar || (ix->component_type != cgltf_component_type_r_8u &&
            ix->component_type != cgltf_component_type_r_16u && ix->component_type != cgltf_component_type_r_32u)) {
            snprintf(err, errlen, "%s: indices must be unsigned integer scalars", path);
            return -1;
        }
        if (!accessor_ok(ix, why, sizeof why)) { snprintf(err, errlen, "%s: %s", path, why); return -1; }
    }
    size_t n = ix ? ix->count : pos->count;
    size_t tris = pr->type == cgltf_primitive_type_triangles ? n / 3 : n >= 3 ? n - 2 : 0;
    if (tris > max_tris - *added) {
        snprintf(err, errlen, "%s: the scene expands to more than %zu triangles (%d per byte of input)", path, max_tris,
                 MS_MAX_TRIS_PER_BYTE);
        return -1;
    }
    /* Normal-mapped primitives: the asset's TANGENT (xyz carried by m, w times the sign of m's determinant:
     * a mirroring transform flips the bitangent), else MikkTSpace over the primitive once it is pushed. */
    const ms_material *mm = material != MS_NO_MATERIAL ? &soup->mats[material] : NULL;
    const int mapped = mm && mm->normal_map;
    const cgltf_accessor *tan = NULL;
    for (size_t i = 0; mapped && i < pr->attributes_count; i++) {
        const cgltf_attribute *a = &pr->attributes[i];
        if (a->type == cgltf_attribute_type_tangent && a->index == 0 && a->data && a->data->type == cgltf_type_vec4 &&
            a->data->count == pos->count && accessor_ok(a->data, why, sizeof why))
            tan = a->data;
    }
    const float det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
    float *t12 = tan && tris ? malloc(tris * 12 * sizeof *t12) : NULL;
    if (tan && tris && !t12) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    const size_t first = soup->n;
    for (size_t t = 0; t < tris; t++) {
        size_t corner[3];
        if (pr->type == cgltf_primitive_type_triangles) { corner[0] = 3 * t; corner[1] = 3 * t + 1; corner[2] = 3 * t + 2; }
        else if (pr->type == cgltf_primitive_type_triangle_strip) { corner[0] = t; corner[1] = t + 1 + (t & 1); corner[2] = t + 2 - (t & 1); }
        else { corner[0] = t + 1; corner[1] = t + 2; corner[2] = 0; }
        float v[9], uv[MS_SOUP_UV_SETS][6], nv[9];
        double vd[9];
        const float *uvp[MS_SOUP_UV_SETS] = { NULL };
        for (int k = 0; k < 3; k++) {
            size_t idx = ix ? cgltf_accessor_read_index(ix, corner[k]) : corner[k];
            if (idx >= pos->count) {
                snprintf(err, errlen, "%s: index %zu is beyond the %zu vertices", path, idx, (size_t)pos->count);
                free(t12);
                return -1;
            }
            if (t12) {
                float q[4] = { 0, 0, 0, 1 }, *o = t12 + 12 * t + 4 * k;
                cgltf_accessor_read_float(tan, idx, q, 4);
                for (int r = 0; r < 3; r++) o[r] = m[r] * q[0] + m[4 + r] * q[1] + m[8 + r] * q[2];
                o[3] = (q[3] < 0.0f) != (det < 0.0f) ? -1.0f : 1.0f;
            }
            float p[3] = { 0, 0, 0 };
            cgltf_accessor_read_float(pos, idx, p, 3);
            for (int r = 0; r < 3; r++) v[3 * k + r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
            /* in double too: a node translation far from the origin (cgltf keeps it as a float) then leaves the
             * mesh's own detail to the scene's frame (scene_frame.c) instead of rounding it away here */
            for (int r = 0; r < 3; r++)
                vd[3 * k + r] = (double)m[r] * p[0] + (double)m[4 + r] * p[1] + (double)m[8 + r] * p[2] + (double)m[12 + r];
            if (nrm) {
                float q[3] = { 0, 0, 0 };
                cgltf_accessor_read_float(nrm, idx, q, 3);
                for (int r = 0; r < 3; r++) nv[3 * k + r] = cof[3 * r] * q[0] + cof[3 * r + 1] * q[1] + cof[3 * r + 2] * q[2];
            }
            for (int st = 0; st < MS_SOUP_UV_SETS; st++) {
                if (!tc[st]) continue;
                uv[st][2 * k] = uv[st][2 * k + 1] = 0.0f;
                cgltf_accessor_read_float(tc[st], idx, uv[st] + 2 * k, 2);
                uvp[st] = uv[st];
            }
        }
        if (ms_soup_push_d(soup, v, vd, uvp, material, nrm ? nv : NULL)) {
            snprintf(err, errlen, "%s: out of memory", path);
            free(t12);
            return -1;
        }
        (*added)++;
    }
    const int trc = !mapped || !tris ? 0 : t12 ? ms_soup_set_tangents(soup, first, tris, t12)
                                               : ms_soup_mikktspace(soup, first, tris, mm->normal_uv);
    free(t12);
    if (trc) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    return 0;
}

/* A buffer's or image's file URI, percent-decoded, resolved inside the folder of the glTF `path` (as cgltf
 * resolves buffers: the glTF's folder and the decoded URI) unless allow; -1 with one line otherwise. */
static int resolve_uri(const char *path, const char *uri, int allow, const char *what, char *out, size_t n, char *err,
                       size_t errlen)
{
    char *dec = strdup(uri);
    if (!dec) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    cgltf_decode_uri(dec);
    char name[320];   /* messages name the URI as written, and decoded when that differs */
    if (strcmp(dec, uri)) snprintf(name, sizeof name, "%s uri '%.200s', percent-decoded,", what, uri);
    else snprintf(name, sizeof name, "%s uri", what);
    const int rc = ms_resolve_inside(path, dec, allow, name, out, n, err, errlen);
    free(dec);
    return rc;
}

/* Every external buffer and image URI inside the glTF's folder, before any file is opened; then the
 * external buffers read from the paths resolved here (cgltf_load_buffers skips buffers with data; its own
 * resolution would put the folder before an allowed absolute path). */
static int load_uris(cgltf_data *d, const cgltf_options *opt, const char *path, int allow, char *err, size_t errlen)
{
    char out[4096], what[64];
    for (int pass = 0; pass < 2; pass++)
        for (size_t i = 0; i < d->buffers_count + (pass ? 0 : d->images_count); i++) {
            const int buf = i < d->buffers_count;
            const char *uri = buf ? d->buffers[i].uri : d->images[i - d->buffers_count].uri;
            if (!uri || !strncmp(uri, "data:", 5) || strstr(uri, "://")) continue;   /* never opened as files */
            snprintf(what, sizeof what, "%s %zu", buf ? "buffer" : "image", buf ? i : i - d->buffers_count);
            if (resolve_uri(path, uri, allow, what, out, sizeof out, err, errlen)) return -1;
            if (!pass || d->buffers[i].data) continue;
            cgltf_size size = d->buffers[i].size;
            void *data = NULL;
            if (read_buffer_file(&opt->memory, &opt->file, out, &size, &data) != cgltf_result_success) {
                snprintf(err, errlen, "%s: buffer %s", path, ((const gltf_ctx *)opt->file.user_data)->why);
                return -1;
            }
            d->buffers[i].data = data;
            d->buffers[i].data_free_method = cgltf_data_free_method_file_release;
        }
    return 0;
}

/* Image i of the glTF as a soup texture: from its buffer view, a data: URI or a file beside the glTF. */
static long load_image(const cgltf_data *d, const cgltf_options *opt, size_t i, const char *path, ms_tri_soup *soup,
                       char *err, size_t errlen)
{
    const cgltf_image *im = &d->images[i];
    char what[64];
    snprintf(what, sizeof what, "image %zu", i);
    char full[600];   /* messages name the glTF (its path cut at 500 bytes) and the image */
    snprintf(full, sizeof full, "%.500s: %s", path, what);
    if (im->buffer_view) {
        const cgltf_buffer_view *v = im->buffer_view;
        if (!v->buffer || !v->buffer->data || !ms_fits(v->offset, v->size, v->buffer->size)) {
            snprintf(err, errlen, "%s: its buffer view exceeds its buffer", full);
            return -1;
        }
        return ms_soup_add_texture_memory(soup, (const unsigned char *)v->buffer->data + v->offset, v->size, full, 0,
                                          err, errlen);
    }
    if (!im->uri) { snprintf(err, errlen, "%s: has neither a uri nor a bufferView", full); return -1; }
    if (!strncmp(im->uri, "data:", 5)) {
        const char *b64 = strstr(im->uri, ";base64,");
        if (!b64) { snprintf(err, errlen, "%s: a data URI that is not base64", full); return -1; }
        b64 += 8;
        size_t n = strlen(b64), size = n / 4 * 3;
        if (n % 4) { snprintf(err, errlen, "%s: a base64 data URI of %zu characters (not a multiple of 4)", full, n); return -1; }
        if (n >= 1 && b64[n - 1] == '=') size--;
        if (n >= 2 && b64[n - 2] == '=') size--;
        void *data = NULL;
        if (size == 0 || cgltf_load_buffer_base64(opt, size, b64, &data) != cgltf_result_success) {
            snprintf(err, errlen, "%s: a bad base64 data URI", full);
            return -1;
        }
        const long r = ms_soup_add_texture_memory(soup, data, size, full, 0, err, errlen);
        opt->memory.free_func(opt->memory.user_data, data);
        return r;
    }
    /* A file (percent-decoded as glTF URIs are) inside the glTF's folder: checked with the buffers' URIs
     * before anything was read (check_uris). */
    if (strstr(im->uri, "://")) { snprintf(err, errlen, "%s: only relative image paths are read", full); return -1; }
    char file[4096];
    if (resolve_uri(path, im->uri, soup->allow_outside_paths, what, file, sizeof file, err, errlen)) return -1;
    return ms_soup_add_texture_file(soup, file, 0, err, errlen);
}

static float clamp01(float x) { return x >= 0.0f ? (x <= 1.0f ? x : 1.0f) : 0.0f; }   /* NaN -> 0 */

static int32_t wrap_of(cgltf_wrap_mode w)
{
    return w == cgltf_wrap_mode_clamp_to_edge ? MS_WRAP_CLAMP : w == cgltf_wrap_mode_mirrored_repeat ? MS_WRAP_MIRROR : MS_WRAP_REPEAT;
}

/* A finite float within +-1e6 (a transform's entries; the scene's validation demands it), else 0. */
static float bounded(float x) { return x >= -1e6f && x <= 1e6f ? x : 0.0f; }

/* The texture of texture view tv (slot names it in warnings: "baseColorTexture", ...) as a soup texture,
 * its UV set and sampling: the sampler's wrap modes and magnification filter (no mipmaps: each pixel is
 * shaded at one point without a footprint, so there is no level of detail to choose; the minification
 * filter is not used) and KHR_texture_transform (its texCoord overriding the view's). -1 with one warning
 * when it cannot be used (the material keeps its factors). Images are decoded once (tex_of). */
static long texture_of(const cgltf_data *d, const cgltf_options *opt, const cgltf_texture_view *tv, const char *path,
                       size_t mi, const char *slot, ms_tri_soup *soup, long *tex_of, int32_t *uv, ms_texture_sampling *sm)
{
    const cgltf_texture *tx = tv->texture;
    if (!tx) return -1;
    /* The texture's `source` first (the extensions' fallback, PNG or JPEG, which any reader decodes), then
     * EXT_texture_webp's WebP (texture.c, libwebp), then KHR_texture_basisu's KTX2: its payloads are mostly
     * Basis Universal (ETC1S, UASTC), which microshadow does not transcode (docs/shading.md); 8-bit levels,
     * plain or Zstandard, decode (texture_ktx2.c), and a Basis payload is one warning naming the file. */
    const cgltf_image *img = tx->image ? tx->image : tx->has_webp && tx->webp_image ? tx->webp_image
                             : tx->has_basisu ? tx->basisu_image : NULL;
    if (!img) {
        ms_warn_material("%s: material %zu: %s: texture %zu has no PNG, JPEG, WebP or KTX2 image: texture ignored", path, mi,
                         slot, (size_t)(tx - d->textures));
        return -1;
    }
    int32_t set = (int32_t)tv->texcoord;
    memset(sm, 0, sizeof *sm);
    if (tv->has_transform) {
        const cgltf_texture_transform *x = &tv->transform;
        if (x->has_texcoord) set = (int32_t)x->texcoord;
        /* uv' = T R S uv (KHR_texture_transform): R rotates the UVs counter-clockwise in the image (v down). */
        const float c = cosf(x->rotation), sn = sinf(x->rotation);
        const float t[6] = { x->scale[0] * c, -x->scale[0] * sn, x->scale[1] * sn, x->scale[1] * c, x->offset[0], x->offset[1] };
        for (int k = 0; k < 6; k++) sm->transform[k] = bounded(t[k]);
        sm->transformed = 1;
    }
    if (tx->sampler) {
        sm->wrap_s = wrap_of(tx->sampler->wrap_s);
        sm->wrap_t = wrap_of(tx->sampler->wrap_t);
        sm->nearest = tx->sampler->mag_filter == cgltf_filter_type_nearest;
    }
    if (set < 0 || set >= MS_MAX_UV_SETS) {
        ms_warn_material("%s: material %zu: %s uses TEXCOORD_%d (at most %d sets): texture ignored", path, mi, slot, (int)set,
                         MS_MAX_UV_SETS - 1);
        return -1;
    }
    const size_t im = (size_t)(img - d->images);
    if (tex_of[im] == -2) {
        char why[1024];
        tex_of[im] = load_image(d, opt, im, path, soup, why, sizeof why);
        if (tex_of[im] < 0) ms_warn_material("%s: texture ignored", why);
    }
    *uv = set;
    return tex_of[im];
}

/* Extensions microshadow implements (KHR_texture_basisu: the fallback source, else its KTX2 image, 8-bit
 * plain or Zstandard levels decoded, Basis payloads named in a warning; EXT_texture_webp: decoded, texture.c;
 * EXT_meshopt_compression and KHR_draco_mesh_compression: decoded, gltf_decode.c; EXT_mesh_gpu_instancing: every instance drawn,
 * walk_nodes); any other in extensionsRequired is an error, in extensionsUsed one warning each saying what is
 * left out. */
static const char *const known_ext[] = { "KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_texture_basisu",
                                         "KHR_mesh_quantization", "KHR_lights_punctual", "EXT_meshopt_compression",
                                         "EXT_mesh_gpu_instancing", "KHR_draco_mesh_compression", "EXT_texture_webp" };
static const struct { const char *name, *left_out; } ext_left_out[] = {
    { "KHR_materials_unlit", "unlit materials are shaded as lit" },
    { "KHR_materials_pbrSpecularGlossiness", "specular-glossiness is ignored (metallic-roughness or the defaults shade)" },
    { "KHR_materials_variants", "only the default materials are used" },
};

static int check_extensions(const cgltf_data *d, const char *path, char *err, size_t errlen)
{
    for (int req = 1; req >= 0; req--) {
        char **names = req ? d->extensions_required : d->extensions_used;
        const size_t n = req ? d->extensions_required_count : d->extensions_used_count;
        for (size_t i = 0; i < n; i++) {
            const char *e = names[i] ? names[i] : "";
            int known = 0;
            for (size_t k = 0; k < sizeof known_ext / sizeof *known_ext; k++) known |= !strcmp(e, known_ext[k]);
            if (known) continue;
            if (req) {
                snprintf(err, errlen, "%s: requires glTF extension %.200s, which microshadow does not implement", path, e);
                return -1;
            }
            const char *what = NULL;
            for (size_t k = 0; k < sizeof ext_left_out / sizeof *ext_left_out; k++)
                if (!strcmp(e, ext_left_out[k].name)) what = ext_left_out[k].left_out;
            if (!what && !strncmp(e, "KHR_materials_", 14)) what = "ignored (the metallic-roughness base layer is shaded)";
            ms_warn_material("%s: glTF extension %.200s is not implemented: %s", path, e, what ? what : "ignored");
        }
    }
    return 0;
}

/* Every material of the glTF (metallic-roughness; the spec's defaults without it) into the soup; images
 * decoded once each, when a material uses them. */
static int load_materials(const cgltf_data *d, const cgltf_options *opt, const char *path, ms_tri_soup *soup,
                          long *mat_of, char *err, size_t errlen)
{
    long *tex_of = malloc((d->images_count ? d->images_count : 1) * sizeof *tex_of);
    if (!tex_of) { snprintf(err, errlen, "%s: out of memory", path); return -1; }
    for (size_t i = 0; i < d->images_count; i++) tex_of[i] = -2;   /* not loaded yet */
    int rc = 0, warned_blend = 0;
    for (size_t i = 0; i < d->materials_count && !rc; i++) {
        const cgltf_material *cm = &d->materials[i];
        ms_material m = { .base_color = { 1, 1, 1, 1 }, .metallic = 1.0f, .roughness = 1.0f, .base_color_texture = -1,
                          .alpha_cutoff = 0.5f, .alpha_texture = -1 };
        long t;
        int32_t set;
        /* A texture that cannot be used is a warning: the material keeps its factors (geometry and
         * visibility do not depend on it). */
        if (cm->has_pbr_metallic_roughness) {
            const cgltf_pbr_metallic_roughness *pb = &cm->pbr_metallic_roughness;
            for (int c = 0; c < 4; c++) m.base_color[c] = clamp01(pb->base_color_factor[c]);
            m.metallic = clamp01(pb->metallic_factor);
            m.roughness = clamp01(pb->roughness_factor);
            if ((t = texture_of(d, opt, &pb->base_color_texture, path, i, "baseColorTexture", soup, tex_of, &set,
                                &m.base_color_sampling)) >= 0) {
                m.base_color_texture = (int32_t)t;
                m.base_color_uv = set;
            }
            if ((t = texture_of(d, opt, &pb->metallic_roughness_texture, path, i, "metallicRoughnessTexture", soup, tex_of,
                                &set, &m.mr_sampling)) >= 0) {
                m.mr_map = 1;
                m.mr_texture = (int32_t)t;
                m.mr_uv = set;
            }
        }
        if ((t = texture_of(d, opt, &cm->normal_texture, path, i, "normalTexture", soup, tex_of, &set, &m.normal_sampling)) >= 0) {
            m.normal_map = 1;
            m.normal_texture = (int32_t)t;
            m.normal_uv = set;
            m.normal_scale = bounded(cm->normal_texture.scale);
        }
        /* Emission: emissiveFactor x KHR_materials_emissive_strength (x emissiveTexture), linear radiance. */
        const float strength = cm->has_emissive_strength ? cm->emissive_strength.emissive_strength : 1.0f;
        int bad_emission = 0;
        for (int c = 0; c < 3; c++) {
            /* bounded like lights' radiance (MS_MAX_RADIANCE), so that sums of shaded radiance stay finite */
            const float e = cm->emissive_factor[c] * strength;
            bad_emission |= !(e >= 0.0f && e <= MS_MAX_RADIANCE);
            m.emissive[c] = e >= 0.0f && e <= MS_MAX_RADIANCE ? e : 0.0f;
        }
        if (bad_emission)
            ms_warn_material("%s: material %zu: emission (emissiveFactor x emissive strength) negative, NaN or above %g: "
                             "left out", path, i, (double)MS_MAX_RADIANCE);
        if ((m.emissive[0] > 0.0f || m.emissive[1] > 0.0f || m.emissive[2] > 0.0f) &&
            (t = texture_of(d, opt, &cm->emissive_texture, path, i, "emissiveTexture", soup, tex_of, &set,
                            &m.emissive_sampling)) >= 0) {
            m.emissive_map = 1;
            m.emissive_texture = (int32_t)t;
            m.emissive_uv = set;
        }
        /* occlusionTexture is not read: it attenuates indirect (ambient) light only (glTF 2.0, 3.9.3), and
         * microshadow computes direct light. */
        /* Alpha testing (docs/shading.md): MASK with its cutoff; BLEND, which a shadow renderer cannot
         * blend, is tested like MASK at the spec's default cutoff 0.5, with one warning per file. */
        if (cm->alpha_mode == cgltf_alpha_mode_mask || cm->alpha_mode == cgltf_alpha_mode_blend) {
            m.alpha_mode = MS_ALPHA_MASK;
            m.alpha_cutoff = cm->alpha_mode == cgltf_alpha_mode_mask ? clamp01(cm->alpha_cutoff) : 0.5f;
            m.alpha_texture = -1;
            if (cm->alpha_mode == cgltf_alpha_mode_blend && !warned_blend) {
                ms_warn("%s: material %zu: alphaMode BLEND is alpha-tested as MASK at cutoff 0.5", path, i);
                warned_blend = 1;
            }
        }
        mat_of[i] = ms_soup_add_material(soup, &m, cm->name);
        if (mat_of[i] < 0) { snprintf(err, errlen, "%s: out of memory, or more than %d materials", path, MS_MAX_MATERIALS); rc = -1; }
    }
    free(tex_of);
    return rc;
}

typedef struct node_item { const cgltf_node *node; float parent[16]; } node_item;

/* The node's KHR_lights_punctual light, placed by its world matrix (column-major): position its origin,
 * direction its -Z axis; extras.radius and extras.angular_diameter_deg read from the extras' JSON text when
 * present. */
static int push_punctual(ms_tri_soup *soup, const cgltf_light *cl, const float world[16], const char *path, char *err,
                         size_t errlen)
{
    ms_punctual *grown = realloc(soup->punctual, (soup->n_punctual + 1) * sizeof *grown);
    if (!grown) { snprintf(err, errlen, "%s: out of memory for its lights", path); return -1; }
    soup->punctual = grown;
    ms_punctual *p = &grown[soup->n_punctual++];
    memset(p, 0, sizeof *p);
    p->type = cl->type == cgltf_light_type_spot ? MS_PUNCTUAL_SPOT
            : cl->type == cgltf_light_type_directional ? MS_PUNCTUAL_DIRECTIONAL : MS_PUNCTUAL_POINT;
    for (int c = 0; c < 3; c++) p->color[c] = isfinite(cl->color[c]) && cl->color[c] > 0.0f ? cl->color[c] : 0.0f;
    p->intensity = isfinite(cl->intensity) && cl->intensity > 0.0f ? cl->intensity : 0.0f;
    double len = 0.0;
    for (int c = 0; c < 3; c++) {
        p->pos[c] = world[12 + c];
        p->dir[c] = -(double)world[8 + c];
        len += p->dir[c] * p->dir[c];
    }
    len = sqrt(len);
    for (int c = 0; c < 3; c++) p->dir[c] = len > 0.0 ? p->dir[c] / len : (c == 2 ? -1.0 : 0.0);
    const char *r = cl->extras.data ? strstr(cl->extras.data, "\"radius\"") : NULL;
    if (r && (r = strchr(r, ':')) != NULL) {
        const double v = strtod(r + 1, NULL);
        if (isfinite(v) && v > 0.0 && v < 1e18) p->radius = (float)v;
    }
    const char *ad = cl->extras.data ? strstr(cl->extras.data, "\"angular_diameter_deg\"") : NULL;
    if (ad && (ad = strchr(ad, ':')) != NULL) {
        const double v = strtod(ad + 1, NULL);   /* checked where the sun is made (scene_punctual.c) */
        p->angular_deg = isfinite(v) && fabs(v) < 1e6 && v != 0.0 ? (float)v : -1.0f;
    }
    p->mesh = soup->cur_mesh;
    return 0;
}

/* The node's camera as the asset's (the first one met), placed by its world matrix: eye its origin, looking
 * along its -Z axis, up its +Y; one without a usable direction or field of view is passed over. */
static void take_camera(ms_tri_soup *soup, const cgltf_camera *c, const float w[16])
{
    ms_asset_camera a;
    memset(&a, 0, sizeof a);
    double dl = 0.0, ul = 0.0;
    for (int k = 0; k < 3; k++) {
        a.eye[k] = w[12 + k];
        a.dir[k] = -(double)w[8 + k];
        a.up[k] = w[4 + k];
        dl += a.dir[k] * a.dir[k];
        ul += a.up[k] * a.up[k];
    }
    if (!(dl > 0.0) || !(ul > 0.0) || !isfinite(dl + ul) || !isfinite(a.eye[0] + a.eye[1] + a.eye[2])) return;
    for (int k = 0; k < 3; k++) { a.dir[k] /= sqrt(dl); a.up[k] /= sqrt(ul); }
    if (c->type == cgltf_camera_type_perspective) {
        a.yfov_deg = (float)(c->data.perspective.yfov * 180.0 / M_PI);
        if (!(a.yfov_deg > 0.0f && a.yfov_deg < 180.0f)) return;
        const float ar = c->data.perspective.aspect_ratio;
        a.aspect = c->data.perspective.has_aspect_ratio && ar > 1e-3f && ar < 1e3f ? ar : 0.0f;
    } else if (c->type == cgltf_camera_type_orthographic) {
        a.ortho = 1;
        a.ymag = c->data.orthographic.ymag;
        const float xm = c->data.orthographic.xmag;
        if (!(a.ymag > 0.0f && a.ymag < 1e18f)) return;
        a.aspect = xm > 0.0f && xm / a.ymag > 1e-3f && xm / a.ymag < 1e3f ? xm / a.ymag : 0.0f;
    } else {
        return;
    }
    a.present = 1;
    soup->camera = a;
}

/* The node's EXT_mesh_gpu_instancing attributes are the extension's: TRANSLATION and SCALE VEC3, ROTATION VEC4
 * (float, or normalized integers for ROTATION, as KHR_mesh_quantization allows), others ignored. 1, or 0 with
 * why. */
static int instancing_ok(const cgltf_node *n, char *why, size_t len)
{
    for (size_t a = 0; a < n->mesh_gpu_instancing.attributes_count; a++) {
        const cgltf_attribute *at = &n->mesh_gpu_instancing.attributes[a];
        const int vec4 = at->name && !strcmp(at->name, "ROTATION");
        const int vec3 = at->name && (!strcmp(at->name, "TRANSLATION") || !strcmp(at->name, "SCALE"));
        if (!at->data) { snprintf(why, len, "an instance attribute has no accessor"); return 0; }
        if ((vec4 && at->data->type != cgltf_type_vec4) || (vec3 && at->data->type != cgltf_type_vec3)) {
            snprintf(why, len, "instance attribute %.40s is not a %s", at->name, vec4 ? "VEC4" : "VEC3");
            return 0;
        }
    }
    return 1;
}

/* world x T R S of instance i (EXT_mesh_gpu_instancing): the node's TRANSLATION, ROTATION (x, y, z, w) and
 * SCALE at i, identity where absent; the same matrix cgltf_node_transform_local makes of a node's TRS. */
static void instance_matrix(const cgltf_node *n, size_t i, const float world[16], float out[16])
{
    cgltf_node tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.rotation[3] = 1.0f;
    tmp.scale[0] = tmp.scale[1] = tmp.scale[2] = 1.0f;
    tmp.has_translation = tmp.has_rotation = tmp.has_scale = 1;
    for (size_t a = 0; a < n->mesh_gpu_instancing.attributes_count; a++) {
        const cgltf_attribute *at = &n->mesh_gpu_instancing.attributes[a];
        if (!at->name) continue;
        if (!strcmp(at->name, "TRANSLATION")) cgltf_accessor_read_float(at->data, i, tmp.translation, 3);
        else if (!strcmp(at->name, "ROTATION")) cgltf_accessor_read_float(at->data, i, tmp.rotation, 4);
        else if (!strcmp(at->name, "SCALE")) cgltf_accessor_read_float(at->data, i, tmp.scale, 3);
    }
    float local[16];
    cgltf_node_transform_local(&tmp, local);
    mat4_mul(out, world, local);
}

/* Depth-first over the node trees without recursion; every node at most once (glTF requires trees,
 * and a node listed twice would expand exponentially: 41 such nodes are 2^40 instances). */
static int walk_nodes(const cgltf_data *d, const long *mat_of, ms_tri_soup *soup, size_t *added, size_t max_tris,
                      const char *path, char *err, size_t errlen)
{
    const cgltf_scene *sc = d->scene ? d->scene : d->scenes_count ? &d->scenes[0] : NULL;
    size_t nn = d->nodes_count;
    unsigned char *seen = calloc(nn ? nn : 1, 1);
    node_item *stack = malloc((nn ? nn : 1) * sizeof *stack);
    int rc = 0;
    if (!seen || !stack) { snprintf(err, errlen, "%s: out of memory", path); rc = -1; goto out; }
    size_t top = 0;
    static const float id[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
    size_t nroots = sc ? sc->nodes_count : nn;
    for (size_t r = 0; r < nroots && !rc; r++) {
        const cgltf_node *root = sc ? sc->nodes[r] : &d->nodes[r];
        if (!sc && root->parent) continue;
        top = 0;
        size_t ri = (size_t)(root - d->nodes);
        if (seen[ri]) { snprintf(err, errlen, "%s: node %zu is reached more than once (glTF nodes form trees)", path, ri); rc = -1; break; }
        seen[ri] = 1;
        stack[top].node = root;
        memcpy(stack[top++].parent, id, sizeof id);
        while (top && !rc) {
            node_item it = stack[--top];
            float local[16], world[16];
            cgltf_node_transform_local(it.node, local);
            mat4_mul(world, it.parent, local);
            if (it.node->light && !rc) rc = push_punctual(soup, it.node->light, world, path, err, errlen);
            if (it.node->camera && !soup->camera.present) take_camera(soup, it.node->camera, world);
            const cgltf_node *nd = it.node;
            char why[128];
            if (nd->mesh && nd->has_mesh_gpu_instancing && !instancing_ok(nd, why, sizeof why)) {
                snprintf(err, errlen, "%s: node %zu: %s", path, (size_t)(nd - d->nodes), why);
                rc = -1;
                break;
            }
            /* GPU instances (EXT_mesh_gpu_instancing; cgltf_validate: every attribute has the same count). Each
             * instance of a mesh emits a triangle or more, so more instances than triangles allowed is an
             * error rather than a long loop (accessors without a view declare any count). */
            const size_t instances = !nd->mesh ? 0 : nd->has_mesh_gpu_instancing ? nd->mesh_gpu_instancing.attributes[0].data->count : 1;
            if (instances > max_tris) {
                snprintf(err, errlen, "%s: node %zu has more GPU instances than the scene may have triangles (%zu)", path,
                         (size_t)(nd - d->nodes), max_tris);
                rc = -1;
                break;
            }
            for (size_t i = 0; i < instances && !rc; i++) {
                float m[16];
                if (nd->has_mesh_gpu_instancing) instance_matrix(nd, i, world, m);
                else memcpy(m, world, sizeof m);
                ms_soup_new_object(soup);   /* each node's mesh, each instance of it, is an object (lightmap UVs per object) */
                for (size_t p = 0; p < nd->mesh->primitives_count && !rc; p++)
                    rc = emit_primitive(d, mat_of, &nd->mesh->primitives[p], m, soup, added, max_tris, path, err, errlen);
            }
            for (size_t c = 0; c < it.node->children_count && !rc; c++) {
                size_t ci = (size_t)(it.node->children[c] - d->nodes);
                if (seen[ci]) {
                    snprintf(err, errlen, "%s: node %zu is reached more than once (glTF nodes form trees)", path, ci);
                    rc = -1;
                    break;
                }
                seen[ci] = 1;
                stack[top].node = it.node->children[c];   /* top < nn: each node is pushed once */
                memcpy(stack[top++].parent, world, sizeof world);
            }
        }
    }
out:
    free(seen);
    free(stack);
    return rc;
}

int ms_mesh_gltf(const char *buf, size_t len, const char *path, ms_tri_soup *soup, size_t *added, char *err,
                 size_t errlen)
{
    *added = 0;
    gltf_ctx g = { 0, GLTF_BUDGET_BASE + GLTF_BUDGET_PER_BYTE * len, len, "" };
    cgltf_options opt;
    memset(&opt, 0, sizeof opt);
    opt.memory.alloc_func = budget_alloc;
    opt.memory.free_func = budget_free;
    opt.memory.user_data = &g;
    opt.file.read = read_buffer_file;
    opt.file.release = release_buffer_file;
    opt.file.user_data = &g;
    cgltf_data *d = NULL;
    long *mat_of = NULL;   /* glTF material -> soup material */
    ms_gltf_dense dense = { 0 };
    cgltf_result r = cgltf_parse(&opt, buf, len, &d);
    if (r != cgltf_result_success) { snprintf(err, errlen, "%s: %s", path, result_text(r)); return -1; }
    int rc = -1;
    if (check_extensions(d, path, err, errlen)) goto out;
    /* Core features a static shadow renderer leaves out: one warning each (docs/shading.md). */
    size_t morphs = 0;
    for (size_t i = 0; i < d->meshes_count; i++)
        for (size_t p = 0; p < d->meshes[i].primitives_count; p++) morphs += d->meshes[i].primitives[p].targets_count > 0;
    if (d->skins_count)
        ms_warn_material("%s: %zu skins are not applied: skinned meshes are drawn in their bind pose, placed by their nodes",
                         path, (size_t)d->skins_count);
    if (morphs) ms_warn_material("%s: morph targets are not applied (%zu primitives have some): base shapes drawn", path, morphs);
    if (d->animations_count)
        ms_warn_material("%s: %zu animations are ignored: the nodes' static transforms are drawn", path, (size_t)d->animations_count);
    /* A data: URI's declared length must fit in its text before cgltf allocates it. */
    for (size_t i = 0; i < d->buffers_count; i++) {
        const char *uri = d->buffers[i].uri;
        const char *comma = uri && !strncmp(uri, "data:", 5) ? strchr(uri, ',') : NULL;
        if (comma && d->buffers[i].size / 3 > strlen(comma + 1) / 4 + 1) {
            snprintf(err, errlen, "%s: buffer %zu declares %zu bytes, more than its data URI holds", path, i, (size_t)d->buffers[i].size);
            goto out;
        }
    }
    if (load_uris(d, &opt, path, soup->allow_outside_paths, err, errlen)) goto out;
    r = cgltf_load_buffers(&opt, d, path);
    if (r != cgltf_result_success) {
        if (g.why[0]) snprintf(err, errlen, "%s: buffer %s", path, g.why);
        else snprintf(err, errlen, "%s: %s", path, result_text(r));
        goto out;
    }
    char why[160];
    if (ms_gltf_meshopt_decode(d, g.limit, why, sizeof why)) { snprintf(err, errlen, "%s: %s", path, why); goto out; }
    /* cgltf_validate reads index data through accessor bounds it computes with wrapping arithmetic:
     * check every accessor with data here first. */
    for (size_t i = 0; i < d->accessors_count; i++) {
        const cgltf_accessor *a = &d->accessors[i];
        const cgltf_buffer_view *v = a->buffer_view;
        if ((a->is_sparse && !ms_gltf_sparse_ok(a, why, sizeof why)) ||
            (a->count && v && (v->data || (v->buffer && v->buffer->data)) && !accessor_ok(a, why, sizeof why))) {
            snprintf(err, errlen, "%s: accessor %zu: %s", path, i, why);
            goto out;
        }
    }
    r = cgltf_validate(d);
    if (r != cgltf_result_success) { snprintf(err, errlen, "%s: %s", path, result_text(r)); goto out; }
    if (ms_gltf_densify(d, g.limit, &dense, why, sizeof why)) { snprintf(err, errlen, "%s: %s", path, why); goto out; }
    mat_of = malloc((d->materials_count ? d->materials_count : 1) * sizeof *mat_of);
    if (!mat_of) { snprintf(err, errlen, "%s: out of memory", path); goto out; }
    if (load_materials(d, &opt, path, soup, mat_of, err, errlen)) goto out;
    rc = walk_nodes(d, mat_of, soup, added, (g.input + 64) * MS_MAX_TRIS_PER_BYTE, path, err, errlen);
out:
    free(mat_of);
    ms_gltf_dense_undo(d, &dense);
    cgltf_free(d);
    return rc;
}
