/* Lightmap UVs for triangles that have none, from xatlas (third_party/xatlas, its C interface). */
#ifndef MS_LIGHTMAP_UNWRAP_H
#define MS_LIGHTMAP_UNWRAP_H
#include <stddef.h>
#include <stdint.h>

/* Unwraps the triangles i of the soup tri (9 floats each) with want[i] != 0 into one atlas of about
 * size x size texels with `padding` texels between charts, and writes their UVs, in [0,1]^2, to
 * uv[6*i .. 6*i+5]; triangles xatlas leaves out (zero area) get NaN. Vertices at the same position are
 * welded first so that charts span connected surfaces. 0, or -1 with a message. */
int ms_lightmap_unwrap(const float *tri, size_t n, const uint8_t *want, int size, int padding, float *uv,
                       char *err, size_t errlen);

#endif
