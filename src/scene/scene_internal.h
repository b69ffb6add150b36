#ifndef MS_SCENE_INTERNAL_H
#define MS_SCENE_INTERNAL_H
#include <stddef.h>

#define MS_DEFAULT_EMISSION 1.0f

typedef struct ms_tri_soup { float *tri; size_t n, cap; } ms_tri_soup;

/* Appends the triangles of a mesh file (any format assimp reads, triangulated, node transforms
 * applied). Fails with a message naming the file if assimp cannot read it or it has no triangles. */
int ms_mesh_load(const char *path, ms_tri_soup *soup, char *err, size_t errlen);
int ms_soup_push(ms_tri_soup *soup, const float v[9]);

#endif
