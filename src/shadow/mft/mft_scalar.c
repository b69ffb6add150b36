/* The portable instance of method mft's block tracer (mft_impl.h). */
#include "mft_impl.h"
