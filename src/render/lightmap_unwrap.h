/* Lightmap UVs for triangles that have none, from xatlas (third_party/xatlas, its C interface). */
#ifndef MS_LIGHTMAP_UNWRAP_H
#define MS_LIGHTMAP_UNWRAP_H
#include <stddef.h>
#include <stdint.h>

/* xatlas's chart-growing weights (xatlas.h, ChartOptions): ms_lightmap_unwrap_tuning_default gives the ones the
 * unwrap uses (and the UV cache's key hashes). */
typedef struct ms_unwrap_tuning {
    float normal_deviation, roundness, straightness, normal_seam, texture_seam, max_cost;
    unsigned max_iterations;
} ms_unwrap_tuning;
void ms_lightmap_unwrap_tuning_default(ms_unwrap_tuning *t);

typedef struct ms_unwrap_info {
    size_t charts;          /* charts xatlas made */
    unsigned atlases;       /* atlases (pages) they were packed into */
    float texels_per_unit;  /* the density they were packed at */
} ms_unwrap_info;

/* Unwraps the triangles i of the soup tri (9 floats each) with want[i] != 0 and writes their UVs to
 * uv[6*i .. 6*i+5]; triangles xatlas leaves out (zero area) get NaN. Each group (group[i]: an object; NULL:
 * one group) is its own xatlas mesh, so xatlas charts them in parallel, and vertices at the same position
 * are welded within it so that charts span connected surfaces (and cross the file's normal seams).
 * density 0: one atlas of about size x size, the UVs in [0,1]^2 of it (the density lowered until one
 * suffices; atlas may be NULL). density > 0: that many texels per unit of tri, in as many size x size
 * atlases as it takes, atlas[i] the one of triangle i and uv in [0,1]^2 of it.
 * 0, or -1 with a message. */
int ms_lightmap_unwrap(const float *tri, size_t n, const uint8_t *want, const uint32_t *group, int size, int padding,
                       float density, float *uv, uint32_t *atlas, ms_unwrap_info *info,
                       char *err, size_t errlen);
#endif
