/* The avx2 instance of the hierarchical penumbra casting engine (hpc_impl.h). */
#include "hpc_impl.h"
