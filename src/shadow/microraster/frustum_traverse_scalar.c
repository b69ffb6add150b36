/* Portable instances of the frustum traversal (frustum_traverse_impl.h, no ISA flags). */
#include "frustum_traverse.h"

#define MS_PERK_IMPL "shadow/microraster/frustum_traverse_impl.h"
#include "core/perk_each.h"
