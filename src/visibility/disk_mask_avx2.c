/* The AVX2 instance of the grid disk mask (disk_mask_impl.h). */
#include "disk_mask_impl.h"
