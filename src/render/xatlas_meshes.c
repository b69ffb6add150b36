/* Meshes handed to xatlas (xatlas_meshes.h). */
#include "xatlas_meshes.h"

xatlasAddMeshError ms_xatlas_add_meshes(xatlasAtlas *atlas, int dim, const float *data, const size_t *vseg,
                                        const uint32_t *index, const size_t *seg, size_t ng)
{
    for (size_t g = 0; g < ng; g++) {
        const uint32_t vertices = (uint32_t)(vseg[g + 1] - vseg[g]), indices = (uint32_t)(3 * (seg[g + 1] - seg[g]));
        const float *v = data + (size_t)dim * vseg[g];
        const uint32_t *ix = index + 3 * seg[g];
        xatlasAddMeshError e;
        if (dim == 2) {
            xatlasUvMeshDecl d;
            xatlasUvMeshDeclInit(&d);
            d.vertexUvData = v;
            d.vertexCount = vertices;
            d.vertexStride = 2 * sizeof(float);
            d.indexData = ix;
            d.indexCount = indices;
            d.indexFormat = XATLAS_INDEX_FORMAT_UINT32;
            e = xatlasAddUvMesh(atlas, &d);
        } else {
            xatlasMeshDecl d;
            xatlasMeshDeclInit(&d);
            d.vertexPositionData = v;
            d.vertexCount = vertices;
            d.vertexPositionStride = 3 * sizeof(float);
            d.indexData = ix;
            d.indexCount = indices;
            d.indexFormat = XATLAS_INDEX_FORMAT_UINT32;
            e = xatlasAddMesh(atlas, &d, (uint32_t)ng);
        }
        if (e != XATLAS_ADD_MESH_ERROR_SUCCESS) return e;
    }
    return XATLAS_ADD_MESH_ERROR_SUCCESS;
}

void ms_xatlas_pack_padding(xatlasPackOptions *po, int padding)
{
    po->bilinear = true;
    po->padding = (uint32_t)ms_chart_padding(padding);
}
