/* Draco-compressed meshes (glTF's KHR_draco_mesh_compression), decoded by Debian's libdraco, the extension's
 * reference decoder, behind a small C interface (draco_decode.cpp: Draco's API is C++). */
#ifndef MS_SCENE_DRACO_DECODE_H
#define MS_SCENE_DRACO_DECODE_H
#include <stddef.h>
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif

typedef struct ms_draco ms_draco;

/* The mesh in bytes[0..n): *points and *faces its counts. NULL with why when it cannot be decoded (corrupt
 * data, a point cloud, out of memory). */
ms_draco *ms_draco_decode(const void *bytes, size_t n, size_t *points, size_t *faces, char *why, size_t wn);

/* The faces' point indices, three per face, into out. */
void ms_draco_faces(const ms_draco *m, uint32_t *out);

/* The attribute with Draco unique id `id` as ncomp floats per point (normalized integers mapped to [0, 1]
 * or [-1, 1]) into out. 0, or -1 when the mesh has no such attribute or it has other than ncomp
 * components. */
int ms_draco_attribute(const ms_draco *m, uint32_t id, int ncomp, float *out);

void ms_draco_free(ms_draco *m);

#ifdef __cplusplus
}
#endif
#endif
