/* The AVX-512 instance (one 16-lane register) of method mft's block tracer (mft_impl.h). */
#include "mft_impl.h"
#include "mft_group_impl.h"
