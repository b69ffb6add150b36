/* The AVX2 instance of the interleaved filter (interleave_filter_impl.h). */
#include "interleave_filter_impl.h"
