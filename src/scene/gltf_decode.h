/* What a glTF's data needs before mesh_gltf.c reads its accessors element by element: buffer views
 * compressed with EXT_meshopt_compression decoded, by meshoptimizer's decoders (the extension's reference
 * implementation, Debian's libmeshoptimizer), and the sparse accessors and Draco-compressed primitives
 * (KHR_draco_mesh_compression, Debian's libdraco) that triangles read written out dense. Every offset, length, count and index is checked against the buffers first, so a hostile file
 * gets one message (why) instead of a read out of bounds; what is allocated counts against the
 * loader's memory budget (d->memory). */
#ifndef MS_SCENE_GLTF_DECODE_H
#define MS_SCENE_GLTF_DECODE_H
#include "cgltf.h"
#include <stddef.h>

/* a + b <= lim without overflow. */
static inline int ms_fits(size_t a, size_t b, size_t lim) { return a <= lim && b <= lim - a; }

/* Decodes every meshopt-compressed buffer view into view->data (which cgltf reads instead of the view's
 * buffer, and cgltf_free frees), at most max_bytes in all. 0, or -1 with why. */
int ms_gltf_meshopt_decode(cgltf_data *d, size_t max_bytes, char *why, size_t n);

/* The sparse parts of accessor a (its indices and values) lie within their buffer views, and those within
 * their buffers. 1, or 0 with why. */
int ms_gltf_sparse_ok(const cgltf_accessor *a, char *why, size_t n);

/* Accessors whose data was written out dense: each one's fields as cgltf parsed them, to put back before
 * cgltf_free. */
typedef struct ms_gltf_dense {
    cgltf_accessor **acc;
    cgltf_accessor *saved;
    cgltf_buffer_view *views;   /* the dense copies' views, one per accessor */
    size_t n;
    const cgltf_accessor *first;   /* d->accessors */
    unsigned char *done;           /* per accessor of d: made dense */
} ms_gltf_dense;

/* The accessors triangles read whose data is not plainly in a buffer view, replaced by dense copies (float
 * or their own component type, tightly packed), at most max_bytes in all:
 *   - every sparse accessor a mesh primitive reads (its attributes and indices) or a node's GPU instances
 *     read: the base view's elements, or zeros, with the sparse values written at their indices (a checked
 *     by ms_gltf_sparse_ok and cgltf_validate before);
 *   - the indices and attributes of every Draco-compressed primitive (KHR_draco_mesh_compression), decoded
 *     by libdraco (draco_decode.h): the faces' point indices, each attribute as floats.
 * 0, or -1 with why (ds then holds what was done, for ms_gltf_dense_undo). */
int ms_gltf_densify(cgltf_data *d, size_t max_bytes, ms_gltf_dense *ds, char *why, size_t n);

/* Puts the accessors back as cgltf parsed them and frees the dense copies. */
void ms_gltf_dense_undo(cgltf_data *d, ms_gltf_dense *ds);

#endif
