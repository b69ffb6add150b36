/* glTF data made readable element by element (gltf_decode.h): meshopt-compressed buffer views decoded,
 * sparse accessors and Draco-compressed primitives made dense. */
#include "gltf_decode.h"
#include "draco_decode.h"
#include <meshoptimizer.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static void *mem_alloc(cgltf_data *d, size_t size)
{
    return d->memory.alloc_func ? d->memory.alloc_func(d->memory.user_data, size) : NULL;
}

static void mem_free(cgltf_data *d, void *p)
{
    if (d->memory.free_func) d->memory.free_func(d->memory.user_data, p);
}

/* The bytes a buffer view reads from, NULL when its buffer has none; `size` bytes from there lie within it. */
static const uint8_t *view_bytes(const cgltf_buffer_view *v)
{
    if (!v) return NULL;
    if (v->data) return (const uint8_t *)v->data;
    if (!v->buffer || !v->buffer->data || !ms_fits(v->offset, v->size, v->buffer->size)) return NULL;
    return (const uint8_t *)v->buffer->data + v->offset;
}

/* The extension's rules for a compressed view (EXT_meshopt_compression, "Compressing buffer views"). */
static const char *meshopt_invalid(const cgltf_buffer_view *v, const cgltf_meshopt_compression *mc)
{
    const int attrs = mc->mode == cgltf_meshopt_compression_mode_attributes;
    const int tris = mc->mode == cgltf_meshopt_compression_mode_triangles;
    const int indices = mc->mode == cgltf_meshopt_compression_mode_indices;
    if (!attrs && !tris && !indices) return "an unknown mode";
    if (!mc->buffer || !mc->buffer->data || !ms_fits(mc->offset, mc->size, mc->buffer->size)) return "data outside its buffer";
    if (mc->stride == 0 || mc->count > SIZE_MAX / mc->stride || mc->count * mc->stride != v->size)
        return "a count and stride that do not make the view's byteLength";
    if (attrs && (mc->stride % 4 || mc->stride > 256)) return "an attribute stride that is not a multiple of 4 up to 256";
    if (!attrs && mc->stride != 2 && mc->stride != 4) return "an index stride other than 2 or 4";
    if (tris && mc->count % 3) return "a triangle count that is not a multiple of 3";
    switch (mc->filter) {
    case cgltf_meshopt_compression_filter_none: return NULL;
    case cgltf_meshopt_compression_filter_octahedral: return attrs && (mc->stride == 4 || mc->stride == 8) ? NULL : "an octahedral filter on a stride other than 4 or 8";
    case cgltf_meshopt_compression_filter_quaternion: return attrs && mc->stride == 8 ? NULL : "a quaternion filter on a stride other than 8";
    case cgltf_meshopt_compression_filter_exponential: return attrs ? NULL : "an exponential filter on indices";
    default: return "an unknown filter";
    }
}

int ms_gltf_meshopt_decode(cgltf_data *d, size_t max_bytes, char *why, size_t n)
{
    size_t used = 0;
    for (size_t i = 0; i < d->buffer_views_count; i++) {
        cgltf_buffer_view *v = &d->buffer_views[i];
        if (!v->has_meshopt_compression || v->data) continue;
        const cgltf_meshopt_compression *mc = &v->meshopt_compression;
        const char *bad = meshopt_invalid(v, mc);
        if (bad) { snprintf(why, n, "meshopt-compressed buffer view %zu has %s", i, bad); return -1; }
        if (v->size > max_bytes - used) {
            snprintf(why, n, "meshopt-compressed buffer views decode to more than %zu bytes", max_bytes);
            return -1;
        }
        void *out = mem_alloc(d, v->size ? v->size : 1);
        if (!out) { snprintf(why, n, "out of memory decoding meshopt-compressed buffer view %zu", i); return -1; }
        const unsigned char *src = (const unsigned char *)mc->buffer->data + mc->offset;
        int rc;
        if (mc->mode == cgltf_meshopt_compression_mode_attributes)
            rc = meshopt_decodeVertexBuffer(out, mc->count, mc->stride, src, mc->size);
        else if (mc->mode == cgltf_meshopt_compression_mode_triangles)
            rc = meshopt_decodeIndexBuffer(out, mc->count, mc->stride, src, mc->size);
        else
            rc = meshopt_decodeIndexSequence(out, mc->count, mc->stride, src, mc->size);
        if (rc != 0) {
            mem_free(d, out);
            snprintf(why, n, "meshopt-compressed buffer view %zu cannot be decoded (corrupt data)", i);
            return -1;
        }
        if (mc->filter == cgltf_meshopt_compression_filter_octahedral) meshopt_decodeFilterOct(out, mc->count, mc->stride);
        if (mc->filter == cgltf_meshopt_compression_filter_quaternion) meshopt_decodeFilterQuat(out, mc->count, mc->stride);
        if (mc->filter == cgltf_meshopt_compression_filter_exponential) meshopt_decodeFilterExp(out, mc->count, mc->stride);
        v->data = out;
        used += v->size;
    }
    return 0;
}

/* Index j of a sparse accessor's indices (ic bytes each, unaligned). */
static size_t sparse_index(const uint8_t *ip, size_t ic, size_t j)
{
    if (ic == 1) return ip[j];
    if (ic == 2) { uint16_t v; memcpy(&v, ip + 2 * j, 2); return v; }
    uint32_t v;
    memcpy(&v, ip + 4 * j, 4);
    return v;
}

int ms_gltf_sparse_ok(const cgltf_accessor *a, char *why, size_t n)
{
    const cgltf_accessor_sparse *s = &a->sparse;
    const size_t elem = cgltf_calc_size(a->type, a->component_type);
    const size_t ic = cgltf_component_size(s->indices_component_type);
    if (s->indices_component_type != cgltf_component_type_r_8u && s->indices_component_type != cgltf_component_type_r_16u &&
        s->indices_component_type != cgltf_component_type_r_32u) {
        snprintf(why, n, "a sparse accessor's indices are not unsigned integers");
        return 0;
    }
    if (s->count == 0 || s->count > a->count || elem == 0) { snprintf(why, n, "a sparse accessor has an invalid count"); return 0; }
    const cgltf_buffer_view *iv = s->indices_buffer_view, *vv = s->values_buffer_view;
    if (!view_bytes(iv) || !view_bytes(vv)) { snprintf(why, n, "a sparse accessor's indices or values lie outside their buffer"); return 0; }
    if (s->count > SIZE_MAX / elem || !ms_fits(s->indices_byte_offset, ic * s->count, iv->size) ||
        !ms_fits(s->values_byte_offset, elem * s->count, vv->size)) {
        snprintf(why, n, "a sparse accessor's indices or values exceed their buffer view");
        return 0;
    }
    const uint8_t *ip = view_bytes(iv) + s->indices_byte_offset;
    /* cgltf_validate reads the indices through typed pointers; glTF requires both parts aligned (comp > 0:
     * elem is). */
    const size_t comp = cgltf_component_size(a->component_type);
    if ((uintptr_t)ip % ic || (uintptr_t)(view_bytes(vv) + s->values_byte_offset) % comp) {
        snprintf(why, n, "a sparse accessor's indices or values are not aligned to their component size");
        return 0;
    }
    for (size_t j = 0; j < s->count; j++) {
        const size_t idx = sparse_index(ip, ic, j);
        if (idx >= a->count) {
            snprintf(why, n, "a sparse accessor's index %zu is past its %zu elements", idx, (size_t)a->count);
            return 0;
        }
    }
    return 1;
}

/* Accessor a written out dense into out (count * elem bytes). 0, or -1 with why. */
static int dense_copy(const cgltf_accessor *a, size_t elem, uint8_t *out, char *why, size_t n)
{
    const uint8_t *base = a->buffer_view ? view_bytes(a->buffer_view) : NULL;
    if (a->buffer_view && !base) { snprintf(why, n, "a sparse accessor's base view has no data"); return -1; }
    if (base)
        for (size_t i = 0; i < a->count; i++) memcpy(out + i * elem, base + a->offset + i * a->stride, elem);
    else
        memset(out, 0, a->count * elem);
    const cgltf_accessor_sparse *s = &a->sparse;
    const uint8_t *ip = view_bytes(s->indices_buffer_view) + s->indices_byte_offset;
    const uint8_t *vp = view_bytes(s->values_buffer_view) + s->values_byte_offset;
    const size_t ic = cgltf_component_size(s->indices_component_type);
    for (size_t j = 0; j < s->count; j++) {
        const size_t idx = sparse_index(ip, ic, j);
        if (idx >= a->count) { snprintf(why, n, "a sparse accessor's index %zu is past its %zu elements", idx, (size_t)a->count); return -1; }
        memcpy(out + idx * elem, vp + j * elem, elem);
    }
    return 0;
}

/* Replaces accessor a's data by the dense copy out (size bytes, elements of elem bytes), recording it in ds. */
static void install(ms_gltf_dense *ds, cgltf_accessor *a, void *out, size_t size, size_t elem)
{
    const size_t i = ds->n++;
    cgltf_buffer_view *v = &ds->views[i];
    memset(v, 0, sizeof *v);
    v->buffer = a->buffer_view ? a->buffer_view->buffer : NULL;
    v->data = out;
    v->size = size;
    ds->acc[i] = a;
    ds->saved[i] = *a;
    ds->done[a - ds->first] = 1;
    a->buffer_view = v;
    a->offset = 0;
    a->stride = elem;
    a->is_sparse = 0;
}

/* Accessor a as installed already (a Draco primitive's accessors may be shared). */
static int installed(const ms_gltf_dense *ds, const cgltf_accessor *a) { return ds->done[a - ds->first]; }

/* Marks accessor a (may be NULL) as read by triangles. */
static void mark_read(const cgltf_data *d, unsigned char *read, const cgltf_accessor *a)
{
    if (a) read[a - d->accessors] = 1;
}

/* Primitive pr's Draco data decoded into its indices and the attributes the Draco map names. 0, or -1. */
static int draco_primitive(cgltf_data *d, const cgltf_primitive *pr, size_t max_bytes, size_t *used, ms_gltf_dense *ds,
                           char *why, size_t n)
{
    const cgltf_draco_mesh_compression *dc = &pr->draco_mesh_compression;
    const uint8_t *bytes = view_bytes(dc->buffer_view);
    if (!bytes) { snprintf(why, n, "a Draco-compressed primitive's buffer view lies outside its buffer"); return -1; }
    if (!pr->indices || pr->type != cgltf_primitive_type_triangles) {
        snprintf(why, n, "a Draco-compressed primitive is not indexed triangles");
        return -1;
    }
    size_t points = 0, faces = 0;
    ms_draco *m = ms_draco_decode(bytes, dc->buffer_view->size, &points, &faces, why, n);
    if (!m) return -1;
    int rc = 0;
    cgltf_accessor *ix = pr->indices;
    if (!installed(ds, ix)) {
        const size_t ic = cgltf_component_size(ix->component_type);
        if (ix->count != 3 * faces || (ic != 1 && ic != 2 && ic != 4) || ix->type != cgltf_type_scalar) {
            snprintf(why, n, "a Draco-compressed primitive's indices accessor does not hold its %zu faces", faces);
            rc = -1;
        } else if (faces > (max_bytes - *used) / 12) {
            snprintf(why, n, "Draco-compressed primitives decode to more than %zu bytes", max_bytes);
            rc = -1;
        } else {
            uint32_t *f = mem_alloc(d, faces ? 12 * faces : 1);
            uint8_t *out = mem_alloc(d, faces ? 3 * faces * ic : 1);
            if (!f || !out) { snprintf(why, n, "out of memory"); rc = -1; }
            if (!rc) {
                ms_draco_faces(m, f);
                for (size_t k = 0; k < 3 * faces && !rc; k++) {
                    if (f[k] >= points || (ic < 4 && f[k] >> (8 * ic))) {
                        snprintf(why, n, "a Draco-compressed primitive's face names point %u of %zu", f[k], points);
                        rc = -1;
                    }
                    const uint16_t h = (uint16_t)f[k];
                    const uint8_t c = (uint8_t)f[k];
                    memcpy(out + k * ic, ic == 1 ? (const void *)&c : ic == 2 ? (const void *)&h : (const void *)&f[k], ic);
                }
            }
            mem_free(d, f);
            if (rc) mem_free(d, out);
            else { install(ds, ix, out, 3 * faces * ic, ic); *used += 12 * faces; }
        }
    }
    /* Each attribute the Draco map names, as floats (the accessor then reads as float, not normalized). */
    for (size_t a = 0; a < pr->attributes_count && !rc; a++) {
        cgltf_accessor *acc = pr->attributes[a].data;
        const cgltf_attribute *da = NULL;
        for (size_t k = 0; k < dc->attributes_count; k++)
            if (pr->attributes[a].name && dc->attributes[k].name && !strcmp(pr->attributes[a].name, dc->attributes[k].name))
                da = &dc->attributes[k];
        if (!da || !acc || installed(ds, acc)) continue;
        const int ncomp = (int)cgltf_num_components(acc->type);
        const uint32_t id = (uint32_t)(da->data - d->accessors);   /* cgltf keeps the Draco id as an accessor index */
        if (acc->count != points || ncomp < 1 || ncomp > 4) {
            snprintf(why, n, "a Draco-compressed primitive's %.40s accessor does not hold its %zu points", pr->attributes[a].name, points);
            rc = -1;
            break;
        }
        if (points > (max_bytes - *used) / (4 * (size_t)ncomp)) {
            snprintf(why, n, "Draco-compressed primitives decode to more than %zu bytes", max_bytes);
            rc = -1;
            break;
        }
        float *out = mem_alloc(d, points ? 4 * (size_t)ncomp * points : 1);
        if (!out) { snprintf(why, n, "out of memory"); rc = -1; break; }
        if (ms_draco_attribute(m, id, ncomp, out)) {
            mem_free(d, out);
            snprintf(why, n, "Draco data has no %d-component attribute %u for %.40s", ncomp, id, pr->attributes[a].name);
            rc = -1;
            break;
        }
        install(ds, acc, out, 4 * (size_t)ncomp * points, 4 * (size_t)ncomp);
        acc->component_type = cgltf_component_type_r_32f;
        acc->normalized = 0;
        *used += 4 * (size_t)ncomp * points;
    }
    ms_draco_free(m);
    return rc;
}

int ms_gltf_densify(cgltf_data *d, size_t max_bytes, ms_gltf_dense *ds, char *why, size_t n)
{
    memset(ds, 0, sizeof *ds);
    size_t cap = 0;
    for (size_t i = 0; i < d->accessors_count; i++) cap += d->accessors[i].is_sparse;
    for (size_t m = 0; m < d->meshes_count; m++)
        for (size_t p = 0; p < d->meshes[m].primitives_count; p++)
            if (d->meshes[m].primitives[p].has_draco_mesh_compression) cap += d->meshes[m].primitives[p].attributes_count + 1;
    if (!cap) return 0;
    ds->first = d->accessors;
    ds->acc = mem_alloc(d, cap * sizeof *ds->acc);
    ds->saved = mem_alloc(d, cap * sizeof *ds->saved);
    ds->views = mem_alloc(d, cap * sizeof *ds->views);
    const size_t na = d->accessors_count ? d->accessors_count : 1;
    ds->done = mem_alloc(d, na);
    unsigned char *read = mem_alloc(d, na);
    if (!ds->acc || !ds->saved || !ds->views || !ds->done || !read) {
        mem_free(d, read);
        snprintf(why, n, "out of memory");
        return -1;
    }
    memset(ds->done, 0, na);
    memset(read, 0, na);
    size_t used = 0;
    int rc = 0;
    for (size_t m = 0; m < d->meshes_count && !rc; m++)
        for (size_t p = 0; p < d->meshes[m].primitives_count && !rc; p++)
            if (d->meshes[m].primitives[p].has_draco_mesh_compression)
                rc = draco_primitive(d, &d->meshes[m].primitives[p], max_bytes, &used, ds, why, n);
    /* The sparse accessors triangles read: every primitive's attributes and indices, every node's instances. */
    for (size_t m = 0; m < d->meshes_count; m++)
        for (size_t p = 0; p < d->meshes[m].primitives_count; p++) {
            const cgltf_primitive *pr = &d->meshes[m].primitives[p];
            mark_read(d, read, pr->indices);
            for (size_t a = 0; a < pr->attributes_count; a++) mark_read(d, read, pr->attributes[a].data);
        }
    for (size_t i = 0; i < d->nodes_count; i++)
        if (d->nodes[i].has_mesh_gpu_instancing)
            for (size_t a = 0; a < d->nodes[i].mesh_gpu_instancing.attributes_count; a++)
                mark_read(d, read, d->nodes[i].mesh_gpu_instancing.attributes[a].data);
    for (size_t i = 0; i < d->accessors_count && !rc; i++) {
        cgltf_accessor *a = &d->accessors[i];
        if (!read[i] || !a->is_sparse) continue;
        const size_t elem = cgltf_calc_size(a->type, a->component_type);
        if (elem == 0 || a->count > (max_bytes - used) / elem) {
            snprintf(why, n, "sparse accessors expand to more than %zu bytes", max_bytes);
            rc = -1;
            break;
        }
        uint8_t *out = mem_alloc(d, a->count ? a->count * elem : 1);
        if (!out) { snprintf(why, n, "out of memory"); rc = -1; break; }
        if (dense_copy(a, elem, out, why, n)) { mem_free(d, out); rc = -1; break; }
        used += a->count * elem;
        install(ds, a, out, a->count * elem, elem);
    }
    mem_free(d, read);
    return rc;
}

void ms_gltf_dense_undo(cgltf_data *d, ms_gltf_dense *ds)
{
    for (size_t i = ds->n; i-- > 0;) {   /* last first: an accessor installed twice gets its first state back */
        mem_free(d, ds->views[i].data);
        *ds->acc[i] = ds->saved[i];
    }
    mem_free(d, ds->acc);
    mem_free(d, ds->saved);
    mem_free(d, ds->views);
    mem_free(d, ds->done);
    memset(ds, 0, sizeof *ds);
}
