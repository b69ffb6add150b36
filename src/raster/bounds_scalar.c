/* Scalar Bounds and Hierarchical kernels for 16x16, 32x32 and 64x64 buffers (bounds_impl.h). */
#include "raster_internal.h"

#define MS_PERK_IMPL "raster/bounds_impl.h"
#include "core/perk_each.h"
