/* Scalar Bounds and Hierarchical kernels for 16x16, 32x32 and 64x64 buffers (bounds_impl.h).
 * Hierarchical blocks: 4x4 blocks of 4x4 samples (k = 16), 8x8 blocks of 4x4 (k = 32, the paper's
 * best), 8x8 blocks of 8x8 (k = 64). */
#include "raster_internal.h"

#define MS_K 16
#define MS_WORD uint16_t
#define MS_BLOCK 4
#include "bounds_impl.h"

#define MS_K 32
#define MS_WORD uint32_t
#define MS_BLOCK 4
#include "bounds_impl.h"

#define MS_K 64
#define MS_WORD uint64_t
#define MS_BLOCK 8
#include "bounds_impl.h"
