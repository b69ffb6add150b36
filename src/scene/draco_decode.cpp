/* Draco-compressed meshes through libdraco's C++ API (draco_decode.h). Nothing of Draco's leaves this file:
 * no exception crosses into the C code (an allocation that fails is a decode that fails). */
#include "draco_decode.h"
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include <cstdio>
#include <memory>
#include <new>

struct ms_draco {
    std::unique_ptr<draco::Mesh> mesh;
};

ms_draco *ms_draco_decode(const void *bytes, size_t n, size_t *points, size_t *faces, char *why, size_t wn)
{
    try {
        draco::DecoderBuffer buf;
        buf.Init(static_cast<const char *>(bytes), n);
        draco::Decoder dec;
        auto r = dec.DecodeMeshFromBuffer(&buf);
        if (!r.ok()) {
            std::snprintf(why, wn, "Draco data cannot be decoded (%.200s)", r.status().error_msg());
            return nullptr;
        }
        std::unique_ptr<ms_draco> m(new ms_draco);
        m->mesh = std::move(r).value();
        if (!m->mesh) { std::snprintf(why, wn, "Draco data holds no mesh"); return nullptr; }
        *points = m->mesh->num_points();
        *faces = m->mesh->num_faces();
        return m.release();
    } catch (const std::bad_alloc &) {
        std::snprintf(why, wn, "out of memory decoding Draco data");
    } catch (...) {
        std::snprintf(why, wn, "Draco data cannot be decoded");
    }
    return nullptr;
}

void ms_draco_faces(const ms_draco *m, uint32_t *out)
{
    const draco::Mesh &mesh = *m->mesh;
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
        for (int k = 0; k < 3; k++) *out++ = mesh.face(f)[k].value();
}

int ms_draco_attribute(const ms_draco *m, uint32_t id, int ncomp, float *out)
{
    const draco::Mesh &mesh = *m->mesh;
    const draco::PointAttribute *a = mesh.GetAttributeByUniqueId(id);
    if (!a || a->num_components() != ncomp) return -1;
    const size_t entries = a->size();   /* a corrupt mapping must not read past the values */
    for (draco::PointIndex p(0); p < mesh.num_points(); ++p, out += ncomp)
        if (a->mapped_index(p).value() >= entries || !a->ConvertValue<float>(a->mapped_index(p), static_cast<int8_t>(ncomp), out)) return -1;
    return 0;
}

void ms_draco_free(ms_draco *m) { delete m; }
