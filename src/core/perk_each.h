/* Includes MS_PERK_IMPL (a path from src/, e.g. "raster/scanline_impl.h") once per buffer width (see
 * perk.h). No include guard: included once per file. */
#include <stdint.h>
#include "perk.h"
#ifndef MS_PERK_IMPL
#error "define MS_PERK_IMPL before including perk_each.h"
#endif

#define MS_K 16
#define MS_WORD uint16_t
#include MS_PERK_IMPL
#undef MS_K
#undef MS_WORD

#define MS_K 32
#define MS_WORD uint32_t
#include MS_PERK_IMPL
#undef MS_K
#undef MS_WORD

#define MS_K 64
#define MS_WORD uint64_t
#include MS_PERK_IMPL
#undef MS_K
#undef MS_WORD

#undef MS_PERK_IMPL
