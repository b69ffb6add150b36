/* Per-mesh transforms of the scene file (mesh_transform.c). */
#ifndef MS_MESH_TRANSFORM_H
#define MS_MESH_TRANSFORM_H
#include "scene_internal.h"
#include <stddef.h>

struct cJSON;
/* The value of a mesh's "transform" key (objname: "meshes[i]" for messages) as a 3x4 row-major affine
 * matrix m (the last row 0 0 0 1): {"translate":[x,y,z], "rotate_deg":[x,y,z], "scale":s|[x,y,z]}
 * (M = T Rz Ry Rx S) or {"matrix":[16 numbers, column-major as in glTF]}. Unknown keys, wrong sizes,
 * non-finite numbers and singular matrices are errors: -1 with one line in err. */
int ms_mesh_transform_parse(const struct cJSON *t, const char *objname, const char *path, double m[12], char *err,
                            size_t errlen);
/* Applies m to triangles [from, to) of the soup: positions, vertex normals (inverse transpose, each keeping
 * its length), normal-map tangents (by m, each keeping its length), and for a negative determinant the
 * winding (corners 1 and 2 swapped with their normals, tangents and UVs) and the tangents' handedness. */
void ms_soup_transform(ms_tri_soup *soup, size_t from, size_t to, const double m[12]);
/* Appends a copy of triangles [from, to) (with cur_mesh as their mesh); -1 when out of memory. */
int ms_soup_copy_range(ms_tri_soup *soup, size_t from, size_t to);

#endif
