/* AVX-512 Scanline kernels for 16x16, 32x32 and 64x64 buffers: scanline_simd_impl.h over
 * simd_avx512.h (this file is compiled with MS_TARGET_AVX512 and the ISA's flags, CMakeLists.txt). */
#include "raster_internal.h"

#define MS_PERK_IMPL "raster/scanline_simd_impl.h"
#include "core/perk_each.h"
