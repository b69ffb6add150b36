/* AVX2 instances (two 8-lane halves) of the micro-rasterization methods' multi-frusta traversal (block_raster_impl.h). */
#include "block_raster.h"

#define MS_PERK_IMPL "shadow/microraster/block_raster_impl.h"
#include "core/perk_each.h"
