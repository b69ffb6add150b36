/* The AVX2 instance (two 8-lane halves) of method mft's block tracer (mft_impl.h). */
#include "mft_impl.h"
#include "mft_group_impl.h"
