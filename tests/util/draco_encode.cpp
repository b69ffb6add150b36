/* tu_draco_encode (draco_encode.h), through libdraco's encoder. */
#include "draco_encode.h"
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <cstring>

size_t tu_draco_encode(const float *pos, const float *uv, size_t nv, const uint32_t *idx, size_t nt, int sequential,
                       unsigned char *out, size_t cap, uint32_t *pos_id, uint32_t *uv_id)
{
    draco::Mesh mesh;
    mesh.set_num_points(static_cast<uint32_t>(nv));
    draco::GeometryAttribute gp, gt;
    gp.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
    gt.Init(draco::GeometryAttribute::TEX_COORD, nullptr, 2, draco::DT_FLOAT32, false, 8, 0);
    const int ap = mesh.AddAttribute(gp, true, static_cast<uint32_t>(nv));
    const int at = mesh.AddAttribute(gt, true, static_cast<uint32_t>(nv));
    for (size_t i = 0; i < nv; i++) {
        mesh.attribute(ap)->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)), pos + 3 * i);
        mesh.attribute(at)->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)), uv + 2 * i);
    }
    for (size_t t = 0; t < nt; t++)
        mesh.AddFace({ draco::PointIndex(idx[3 * t]), draco::PointIndex(idx[3 * t + 1]), draco::PointIndex(idx[3 * t + 2]) });
    draco::Encoder enc;
    enc.SetEncodingMethod(sequential ? draco::MESH_SEQUENTIAL_ENCODING : draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer buf;
    if (!enc.EncodeMeshToBuffer(mesh, &buf).ok() || buf.size() > cap) return 0;
    std::memcpy(out, buf.data(), buf.size());
    *pos_id = mesh.attribute(ap)->unique_id();
    *uv_id = mesh.attribute(at)->unique_id();
    return buf.size();
}
