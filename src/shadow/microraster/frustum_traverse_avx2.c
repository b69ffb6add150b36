/* AVX2 instances of the frustum traversal (frustum_traverse_impl.h with MS_TARGET_AVX2; chosen at run
 * time). */
#include "frustum_traverse.h"

#define MS_PERK_IMPL "shadow/microraster/frustum_traverse_impl.h"
#include "core/perk_each.h"
