/* Micro-rasterization of triangles into a k x k occlusion buffer on the light (Woop 2010, sec. 3-5).
 *
 * A frame holds what is shared by every triangle seen from one projection centre C: the world ->
 * light-index transform, the inverse of (ds, dt, p0 - C) for the pixel's sample grid (pattern.h), so that
 * C goes to the origin, the light plane to z = 1 and sample (i,j) to (i, j, 1). A kernel clears, in the
 * buffer, the bit of every sample whose segment C -> sample the triangle blocks at a segment parameter
 * in [near, far] (z = parameter along the segment; near > 0 keeps the receiver's own triangle and its
 * coplanar neighbours out, far = 1 is the light plane).
 *
 * Buffers: k = 16: uint16_t[16], k = 32: uint32_t[32], k = 64: uint64_t[64]; word j is scanline j, bit i
 * is sample i; 1 = visible, 0 = occluded. */
#ifndef MS_RASTER_H
#define MS_RASTER_H
#include <stdint.h>
#include "microshadow.h"
#include "light/pattern.h"

typedef struct ms_raster_frame {
    float m[3][3];      /* light-index coords of world point X: m * (X - c) */
    float mt[3][3];     /* rows ds, dt, p0 - c: the transpose of m's inverse, for world edge normals */
    float c[3];
    float near, far;    /* segment parameter range that occludes */
    int k;
    int cull_backfaces; /* 1: discard triangles facing away from C (closed meshes only) */
    const void *alpha;  /* the caller's alpha-test context (src/visibility/alpha.h), NULL (ms_raster_frame_init):
                         * every triangle opaque. The kernels never read it. */
} ms_raster_frame;

/* Returns 0, or -1 if the frame is degenerate (C on the light plane). */
int ms_raster_frame_init(ms_raster_frame *f, const float c[3], const ms_grid *g, float near, float far,
                         int cull_backfaces);

typedef enum ms_kernel_id {
    MS_KERNEL_SCANLINE = 0,
    MS_KERNEL_BOUNDS = 1,
    MS_KERNEL_HIERARCHICAL = 2,
    MS_KERNEL_COUNT
} ms_kernel_id;

/* Rasterizes one triangle (9 floats, world space) into buf. */
typedef void (*ms_raster_fn)(const ms_raster_frame *f, const float tri[9], void *buf);

/* The fastest variant of the kernel for k that this CPU runs at or below `cap` (MS_ISA_AUTO: no cap);
 * *chosen (may be NULL) is set to its ISA. Scanline has SIMD kernels for AVX2 and AVX-512; Bounds and
 * Hierarchical, the paper's baselines, are their portable C compiled for each ISA (identical buffers).
 * NULL for a k other than 16, 32, 64. */
ms_raster_fn ms_raster_kernel(ms_kernel_id id, int k, ms_isa cap, ms_isa *chosen);
/* Exactly the given variant (MS_ISA_SCALAR, _AVX2, _AVX512), e.g. to test or time AVX2 on an AVX-512
 * machine. NULL when the CPU lacks that ISA, for MS_ISA_AUTO, or when k is not 16, 32, 64. */
ms_raster_fn ms_raster_kernel_isa(ms_kernel_id id, int k, ms_isa isa);
const char *ms_kernel_name(ms_kernel_id id);

/* Clears, in a k x k buffer, every sample (i, j) with e . (i, j, 1) >= 0 (the Scanline kernel's setup and
 * row loop for one edge: ties go to the cleared side, as for a triangle's edges). */
void ms_raster_clear_halfplane(int k, const float e[3], void *buf);

void ms_buffer_fill_visible(void *buf, int k);
int ms_buffer_all_occluded(const void *buf, int k);
int ms_buffer_visible_count(const void *buf, int k);

#endif
