/* Meshes handed to xatlas (xatlas_meshes.c), the one place that fills its mesh declarations: the lightmap
 * unwrap's positions (lightmap_unwrap.c) and the packer's charts and regions as UV meshes (atlas_xpack.c). */
#ifndef MS_XATLAS_MESHES_H
#define MS_XATLAS_MESHES_H
#include <stddef.h>
#include <stdint.h>
#include <xatlas_c.h>

/* Adds ng meshes to atlas. Mesh g has the vertices [vseg[g], vseg[g + 1]) of data, dim floats each (3: positions,
 * added with xatlasAddMesh for charting; 2: UVs of charts already cut, added with xatlasAddUvMesh for packing),
 * and the triangles [seg[g], seg[g + 1]) of index (3 entries each, counted from the mesh's first vertex).
 * XATLAS_ADD_MESH_ERROR_SUCCESS, or xatlas's error for the first mesh it refused (the rest are not added). */
xatlasAddMeshError ms_xatlas_add_meshes(xatlasAtlas *atlas, int dim, const float *data, const size_t *vseg,
                                        const uint32_t *index, const size_t *seg, size_t ng);

#endif
