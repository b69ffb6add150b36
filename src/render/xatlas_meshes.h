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

/* The padding of one chart for `padding` texels between charts, the one place that maps the bake's padding
 * to xatlas's and the regions' packer's: each chart's bilinear footprint (every texel a bilinear lookup inside
 * it reads, its centre within one texel of the chart's triangles) is packed grown by this many texels
 * without overlap, so two footprints lie at least `padding` texels apart. With 0 they may touch: the packer
 * then moves any chart whose exact footprint shares a texel with another's (atlas_footprints.h; xatlas's own
 * footprint test is approximate), and the bake's dilation fills each footprint from its own chart. */
static inline int ms_chart_padding(int padding) { return padding > 0 ? (padding + 1) / 2 : 0; }

/* xatlas's pack options for `padding`: bilinear footprints grown by ms_chart_padding. */
void ms_xatlas_pack_padding(xatlasPackOptions *po, int padding);

#endif
