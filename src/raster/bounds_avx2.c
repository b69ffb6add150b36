/* Bounds and Hierarchical (bounds_impl.h) compiled for AVX2 + FMA: the same C as bounds.c, so the same
 * roundings (no contraction, -ffp-contract=off) and the same buffers bit for bit, with the compiler's
 * vector code and roundss instead of baseline x86-64. They are the paper's baselines: the renderer's
 * "bounds" and "hierarchical" methods and Figure 2 use them compiled for the host, as before the portable
 * files lost -march=native. */
#include "raster_internal.h"

#define MS_PERK_IMPL "raster/bounds_impl.h"
#include "core/perk_each.h"
